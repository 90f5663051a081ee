//! A pinhole camera and thesis 000's camera flight: after each frame the camera
//! advances (default 10 cm) and turns right (default 0.25°) about its up axis;
//! the light optionally moves (default 3 cm along each axis).

use glam::{Quat, Vec3};

/// A pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Camera {
    /// Eye position.
    pub position: [f32; 3],
    /// Viewing direction.
    pub direction: [f32; 3],
    /// Up vector.
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_y: f32,
    /// Image size in pixels (width, height).
    pub resolution: [u32; 2],
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            position: [0.0, 0.0, 5.0],
            direction: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            fov_y: 60.0,
            resolution: [512, 512],
        }
    }
}

/// A camera ray through a pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (unit length).
    pub dir: Vec3,
}

impl Camera {
    /// The orthonormal frame (right, up, forward).
    pub fn frame(&self) -> (Vec3, Vec3, Vec3) {
        let f = Vec3::from(self.direction).normalize();
        let r = f.cross(Vec3::from(self.up)).normalize();
        let u = r.cross(f);
        (r, u, f)
    }

    /// The ray through the centre of pixel (x, y); y = 0 is the top row.
    pub fn ray(&self, x: u32, y: u32) -> Ray {
        let (r, u, f) = self.frame();
        let [w, h] = self.resolution;
        let tan = (self.fov_y.to_radians() * 0.5).tan();
        let aspect = w as f32 / h as f32;
        let px = ((x as f32 + 0.5) / w as f32 * 2.0 - 1.0) * tan * aspect;
        let py = (1.0 - (y as f32 + 0.5) / h as f32 * 2.0) * tan;
        Ray { origin: Vec3::from(self.position), dir: (f + px * r + py * u).normalize() }
    }
}

/// A camera flight.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Flight {
    /// Frames.
    pub frames: u32,
    /// Metres the camera advances after each frame.
    pub forward: f32,
    /// Degrees the camera turns right after each frame.
    pub yaw_deg: f32,
    /// Whether the light moves.
    pub move_light: bool,
    /// Metres the light moves per frame along each axis.
    pub light_step: [f32; 3],
}

impl Default for Flight {
    fn default() -> Self {
        Flight { frames: 50, forward: 0.1, yaw_deg: 0.25, move_light: false, light_step: [0.03, 0.03, 0.03] }
    }
}

impl Flight {
    /// The camera at frame `f` (frame 0 is `start`).
    pub fn camera(&self, start: &Camera, f: u32) -> Camera {
        let mut c = *start;
        let up = Vec3::from(start.up).normalize();
        let turn = Quat::from_axis_angle(up, -self.yaw_deg.to_radians());
        for _ in 0..f {
            let d = Vec3::from(c.direction).normalize();
            c.position = (Vec3::from(c.position) + d * self.forward).into();
            c.direction = (turn * d).into();
        }
        c
    }

    /// Offset of the light at frame `f`.
    pub fn light_offset(&self, f: u32) -> Vec3 {
        if self.move_light { Vec3::from(self.light_step) * f as f32 } else { Vec3::ZERO }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn flight_advances_and_turns_right() {
        let start = Camera::default(); // looking down -z, y up: right is +x
        let fl = Flight::default();
        let c = fl.camera(&start, 1);
        assert_relative_eq!(c.position[2], 4.9, epsilon = 1e-6);
        assert!(c.direction[0] > 0.0, "turned right: {:?}", c.direction);
        let c49 = fl.camera(&start, 49);
        let turned = Vec3::from(c49.direction).angle_between(Vec3::from(start.direction)).to_degrees();
        assert_relative_eq!(turned, 49.0 * 0.25, epsilon = 1e-3);
    }

    #[test]
    fn centre_ray_looks_forward() {
        let c = Camera { resolution: [2, 2], ..Camera::default() };
        let r = c.ray(0, 0);
        assert!(r.dir.x < 0.0 && r.dir.y > 0.0 && r.dir.z < 0.0, "top-left pixel: {:?}", r.dir);
        assert_relative_eq!(r.dir.length(), 1.0, epsilon = 1e-6);
    }
}
