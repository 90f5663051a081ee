//! Frame buffers (linear RGB, f32), written as PNG (sRGB, with exposure) or
//! EXR (linear float), and image comparison for regression tests.

use std::path::Path;

/// A linear-RGB image.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameBuffer {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, row by row from the top.
    pub pixels: Vec<[f32; 3]>,
}

/// Errors writing or reading images.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// PNG encoding or decoding failed.
    #[error("{path}: {msg}")]
    Io {
        /// The file.
        path: String,
        /// What failed.
        msg: String,
    },
    /// Images of different sizes were compared.
    #[error("image sizes differ: {0}x{1} and {2}x{3}")]
    Size(u32, u32, u32, u32),
}

fn srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 }
}

fn linear(x: f32) -> f32 {
    if x <= 0.040_45 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) }
}

impl FrameBuffer {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        FrameBuffer { width, height, pixels: vec![[0.0; 3]; (width * height) as usize] }
    }

    /// Pixel (x, y).
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Sets pixel (x, y).
    pub fn set(&mut self, x: u32, y: u32, c: [f32; 3]) {
        let i = (y * self.width + x) as usize;
        self.pixels[i] = c;
    }

    /// 8-bit sRGB bytes after scaling by 2^exposure.
    pub fn to_srgb8(&self, exposure: f32) -> Vec<u8> {
        let k = exposure.exp2();
        self.pixels.iter().flat_map(|p| p.map(|c| (srgb(c * k) * 255.0 + 0.5) as u8)).collect()
    }

    /// Writes a PNG (sRGB, 8 bits per channel).
    pub fn write_png(&self, path: &Path, exposure: f32) -> Result<(), ImageError> {
        image::save_buffer(path, &self.to_srgb8(exposure), self.width, self.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| ImageError::Io { path: path.display().to_string(), msg: e.to_string() })
    }

    /// Reads a PNG back into linear RGB.
    pub fn read_png(path: &Path) -> Result<Self, ImageError> {
        let img =
            image::open(path).map_err(|e| ImageError::Io { path: path.display().to_string(), msg: e.to_string() })?;
        let rgb = img.to_rgb8();
        let (w, h) = rgb.dimensions();
        let pixels = rgb.pixels().map(|p| p.0.map(|c| linear(c as f32 / 255.0))).collect();
        Ok(FrameBuffer { width: w, height: h, pixels })
    }

    /// Writes an OpenEXR file (linear, 32-bit float RGB).
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        exr::prelude::write_rgb_file(path, self.width as usize, self.height as usize, |x, y| {
            let p = self.get(x as u32, y as u32);
            (p[0], p[1], p[2])
        })
        .map_err(|e| ImageError::Io { path: path.display().to_string(), msg: e.to_string() })
    }
}

/// Differences between two images.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Mean absolute difference per channel.
    pub mean_abs: f64,
    /// Mean relative squared error: (a − b)² / (b² + 0.01), averaged.
    pub rel_mse: f64,
    /// Largest absolute channel difference.
    pub max_abs: f64,
}

/// Compares `a` with the reference `b`.
pub fn compare(a: &FrameBuffer, b: &FrameBuffer) -> Result<Comparison, ImageError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(ImageError::Size(a.width, a.height, b.width, b.height));
    }
    let (mut abs, mut rel, mut max) = (0.0f64, 0.0f64, 0.0f64);
    let n = (a.pixels.len() * 3).max(1) as f64;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let d = (p[c] - q[c]) as f64;
            abs += d.abs();
            rel += d * d / ((q[c] as f64).powi(2) + 0.01);
            max = max.max(d.abs());
        }
    }
    Ok(Comparison { mean_abs: abs / n, rel_mse: rel / n, max_abs: max })
}

/// Per-pixel statistical test of a noisy estimate against a reference with a
/// per-pixel variance image: the fraction of channel values whose z-score
/// |a − b| / sqrt(var + floor) exceeds `z`. (A renderer that agrees in
/// expectation fails about 0.3 % of channels at z = 3.)
pub fn z_test(a: &FrameBuffer, reference: &FrameBuffer, variance: &FrameBuffer, z: f64) -> Result<f64, ImageError> {
    for o in [reference, variance] {
        if (a.width, a.height) != (o.width, o.height) {
            return Err(ImageError::Size(a.width, a.height, o.width, o.height));
        }
    }
    let mut fail = 0usize;
    for i in 0..a.pixels.len() {
        for c in 0..3 {
            let d = (a.pixels[i][c] - reference.pixels[i][c]).abs() as f64;
            let s = ((variance.pixels[i][c] as f64) + 1e-8).sqrt();
            if d / s > z {
                fail += 1;
            }
        }
    }
    Ok(fail as f64 / (a.pixels.len() * 3).max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_and_png() {
        let mut f = FrameBuffer::new(4, 2);
        f.set(1, 1, [0.5, 0.25, 1.0]);
        let dir = std::env::temp_dir().join(format!("warplight-img-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.png");
        f.write_png(&p, 0.0).unwrap();
        let g = FrameBuffer::read_png(&p).unwrap();
        let c = compare(&g, &f).unwrap();
        assert!(c.max_abs < 0.01, "{c:?}");
        f.write_exr(&dir.join("a.exr")).unwrap();
        assert!(std::fs::metadata(dir.join("a.exr")).unwrap().len() > 0);
    }

    #[test]
    fn comparison_and_z_test() {
        let a = FrameBuffer { width: 1, height: 2, pixels: vec![[1.0; 3], [0.0; 3]] };
        let b = FrameBuffer { width: 1, height: 2, pixels: vec![[1.0; 3], [0.1; 3]] };
        let c = compare(&a, &b).unwrap();
        assert!((c.mean_abs - 0.05).abs() < 1e-6 && (c.max_abs - 0.1).abs() < 1e-6);
        let var = FrameBuffer { width: 1, height: 2, pixels: vec![[0.0001; 3], [0.0001; 3]] };
        // the second pixel is 10 standard deviations off
        assert!((z_test(&a, &b, &var, 3.0).unwrap() - 0.5).abs() < 1e-9);
        assert!(compare(&a, &FrameBuffer::new(2, 2)).is_err());
    }
}
