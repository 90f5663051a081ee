//! Charts from plain data, drawn with `plotters` as SVG or PNG: grouped bars
//! with a tolerance band per group ([`Bars`]: ours beside a thesis' value),
//! lines ([`Lines`]: a counter along a camera flight) and scatter plots
//! ([`Scatter`]: speed against accuracy, one series per method). This module
//! knows nothing of tables or results files; `warplight chart` turns those
//! into the data drawn here.
//!
//! Series take their colours in order from [`PALETTE`] (Okabe–Ito, safe for
//! colour-blind readers); a legend above the plot names them. PNG text is
//! drawn with DejaVu Sans, embedded in the binary; SVG text names the generic
//! `sans-serif` family and needs no font file.
//!
//! Every SVG states how values map to pixels, in a comment right after its
//! opening tag:
//!
//! ```text
//! <!-- warplight-chart kind=bars x-pixels=86,1107 y-pixels=452,97 x-range=0,8 y-range=-20,180 x-scale=linear y-scale=linear -->
//! ```
//!
//! `x-pixels` are the pixel columns of the low and the high end of `x-range`,
//! `y-pixels` the pixel rows of the low and the high end of `y-range`. A value
//! maps linearly between them (on a `log` scale its base-10 logarithm does)
//! and is rounded to the nearest pixel, so every mark reads back to within
//! half a pixel:
//!
//! - bars: group `i` spans x in `[i, i + 1]`; each value is a filled `<rect>`
//!   in its series' colour inside that span, series left to right, from the
//!   zero line to the value; a band is a translucent grey `<rect>` across the
//!   span from its low to its high end;
//! - lines: a `<polyline>` per series and a filled `<circle>` per point;
//! - scatter: a filled `<circle>` per point (and a `<polyline>` per series
//!   when `connect` is set).
//!
//! Marks lie inside the plot area; the legend's swatches lie above it.

use std::path::Path;
use std::sync::LazyLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters_backend::{BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind};
use serde::{Deserialize, Serialize};

/// The series' colours, in order (Okabe & Ito's palette: blue, orange, bluish
/// green, vermillion, sky blue, reddish purple, yellow, black; then a brown,
/// so that a chart of eight methods and a reference line shows nine colours,
/// none the tolerance band's grey); series past the ninth take them again.
pub const PALETTE: [(u8, u8, u8); 9] = [
    (0x00, 0x72, 0xB2),
    (0xE6, 0x9F, 0x00),
    (0x00, 0x9E, 0x73),
    (0xD5, 0x5E, 0x00),
    (0x56, 0xB4, 0xE9),
    (0xCC, 0x79, 0xA7),
    (0xF0, 0xE4, 0x42),
    (0x00, 0x00, 0x00),
    (0x8C, 0x56, 0x4B),
];

/// The colour of tolerance bands (drawn at [`BAND_OPACITY`]).
pub const BAND_COLOUR: (u8, u8, u8) = (0x99, 0x99, 0x99);

/// The opacity of tolerance bands.
pub const BAND_OPACITY: f64 = 0.35;

/// The size charts are drawn at unless told otherwise (bars grow with their groups, see [`Chart::default_size`]).
pub const DEFAULT_SIZE: (u32, u32) = (960, 540);

/// DejaVu Sans (assets/fonts/, Bitstream Vera licence): the PNG text and the text measurements of the layout.
const FONT_BYTES: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

static FONT: LazyLock<FontRef<'static>> =
    LazyLock::new(|| FontRef::try_from_slice(FONT_BYTES).expect("the embedded DejaVu Sans is a valid font"));

/// One series of bars: a value per group (`None`: no bar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BarSeries {
    /// Name in the legend.
    pub name: String,
    /// One value per group.
    pub values: Vec<Option<f64>>,
}

/// Grouped bars: per group (an x category) one bar per series, and behind them
/// an optional band (a tolerance around a reference value).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bars {
    /// Title (`\n` breaks lines; long lines wrap).
    pub title: String,
    /// The y axis' label.
    pub y_label: String,
    /// The groups' labels, left to right (`scene6 / Stackless`).
    pub groups: Vec<String>,
    /// The series.
    pub series: Vec<BarSeries>,
    /// Per group, the band's low and high end; empty: no bands.
    #[serde(default)]
    pub bands: Vec<Option<(f64, f64)>>,
    /// The band's name in the legend (`thesis ± tolerance`).
    #[serde(default)]
    pub band_label: String,
}

/// A named series of (x, y) points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// Name in the legend.
    pub name: String,
    /// Points, in the order they are joined.
    pub points: Vec<(f64, f64)>,
}

/// Lines: each series joined in order, a dot per point (the y axis starts at zero).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Lines {
    /// Title.
    pub title: String,
    /// The x axis' label.
    pub x_label: String,
    /// The y axis' label.
    pub y_label: String,
    /// The series.
    pub series: Vec<Series>,
}

/// A scatter plot, such as speed against accuracy (x: seconds or samples,
/// y: error), one series per method. As JSON:
///
/// ```json
/// {"title": "Error against time", "x_label": "seconds", "y_label": "RMSE",
///  "log_x": false, "log_y": true,
///  "series": [{"name": "method A", "points": [[0.5, 0.1], [1.0, 0.05]]}]}
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scatter {
    /// Title.
    pub title: String,
    /// The x axis' label.
    pub x_label: String,
    /// The y axis' label.
    pub y_label: String,
    /// A logarithmic x axis (values must be positive).
    #[serde(default)]
    pub log_x: bool,
    /// A logarithmic y axis (values must be positive).
    #[serde(default)]
    pub log_y: bool,
    /// Join each series' points in order.
    #[serde(default)]
    pub connect: bool,
    /// The series.
    pub series: Vec<Series>,
}

/// A chart of any kind.
#[derive(Debug, Clone, PartialEq)]
pub enum Chart {
    /// Grouped bars.
    Bars(Bars),
    /// Lines.
    Lines(Lines),
    /// A scatter plot.
    Scatter(Scatter),
}

/// What went wrong drawing a chart.
#[derive(Debug, thiserror::Error)]
pub enum ChartError {
    /// Nothing to draw.
    #[error("nothing to draw: {0}")]
    Empty(String),
    /// Data the chart cannot show.
    #[error("{0}")]
    Data(String),
    /// An output name that is neither .svg nor .png.
    #[error("{file}: charts are written as .svg or .png, not {ext}")]
    Format {
        /// The file.
        file: String,
        /// Its extension (or "no extension").
        ext: String,
    },
    /// A size too small or too large to draw.
    #[error("size {0}x{1}: charts are 320x240 to 8000x8000 pixels")]
    Size(u32, u32),
    /// plotters failed.
    #[error("drawing the chart: {0}")]
    Draw(String),
    /// The output could not be written.
    #[error("{file}: {msg}")]
    Write {
        /// The file.
        file: String,
        /// What went wrong.
        msg: String,
    },
}

/// An output format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// SVG text.
    Svg,
    /// A PNG image.
    Png,
}

impl Format {
    /// The format an output file's extension asks for (`.svg` or `.png`, any case).
    pub fn of(path: &Path) -> Result<Format, ChartError> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            other => Err(ChartError::Format {
                file: path.display().to_string(),
                ext: other.map_or("no extension".into(), |e| format!(".{e}")),
            }),
        }
    }
}

/// What went wrong writing charts with their data ([`write_charts`]).
#[derive(Debug, thiserror::Error)]
pub enum WriteChartsError {
    /// A chart could not be drawn.
    #[error(transparent)]
    Chart(#[from] ChartError),
    /// A chart's data or the summary could not be turned into JSON.
    #[error("{file}: {source}")]
    Json {
        /// The file it was for.
        file: String,
        /// What went wrong.
        source: serde_json::Error,
    },
    /// A file could not be written (the message names it).
    #[error("{0}")]
    Write(String),
}

/// The files [`write_charts`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct WrittenCharts {
    /// Per chart, in order: its title, its SVG and its JSON.
    pub charts: Vec<(String, std::path::PathBuf, std::path::PathBuf)>,
    /// `STEM-summary.json`.
    pub summary: std::path::PathBuf,
}

/// Writes each named scatter chart as `STEM-NAME.svg` with its data beside it
/// as `STEM-NAME.json` (`warplight chart scatter` redraws it), then `summary`
/// as `STEM-summary.json`, every file through
/// [`crate::files::write_atomically`].
pub fn write_charts<N: std::fmt::Display>(
    stem: &Path,
    charts: impl IntoIterator<Item = (N, Scatter)>,
    summary: &serde_json::Value,
) -> Result<WrittenCharts, WriteChartsError> {
    let file = |suffix: &str| std::path::PathBuf::from(format!("{}-{suffix}", stem.display()));
    fn json_of<T: Serialize>(f: &Path, v: &T) -> Result<String, WriteChartsError> {
        serde_json::to_string_pretty(v)
            .map_err(|source| WriteChartsError::Json { file: f.display().to_string(), source })
    }
    let mut out = WrittenCharts { charts: Vec::new(), summary: file("summary.json") };
    for (name, chart) in charts {
        let json = file(&format!("{name}.json"));
        crate::files::write_atomically(&json, json_of(&json, &chart)?.as_bytes()).map_err(WriteChartsError::Write)?;
        let svg = file(&format!("{name}.svg"));
        let chart = Chart::Scatter(chart);
        crate::files::write_atomically(&svg, chart.svg(chart.default_size())?.as_bytes())
            .map_err(WriteChartsError::Write)?;
        out.charts.push((chart.title().to_string(), svg, json));
    }
    crate::files::write_atomically(&out.summary, json_of(&out.summary, summary)?.as_bytes())
        .map_err(WriteChartsError::Write)?;
    Ok(out)
}

impl Chart {
    /// The chart's title.
    pub fn title(&self) -> &str {
        match self {
            Chart::Bars(b) => &b.title,
            Chart::Lines(l) => &l.title,
            Chart::Scatter(s) => &s.title,
        }
    }

    /// The size to draw at: [`DEFAULT_SIZE`], wider for bars with many groups
    /// and taller where their labels stand on end.
    pub fn default_size(&self) -> (u32, u32) {
        let Chart::Bars(b) = self else { return DEFAULT_SIZE };
        let n = b.groups.len().max(1) as f64;
        let w = (200.0 + 56.0 * n).clamp(DEFAULT_SIZE.0 as f64, 4000.0);
        let slot = (w - 140.0) / n;
        let widest = b.groups.iter().map(|g| text_width(g, TICK_SIZE)).fold(0.0, f64::max);
        let h = if widest <= slot - 6.0 { DEFAULT_SIZE.1 as f64 } else { 440.0 + widest.min(MAX_LABEL) };
        (w.round() as u32, h.round() as u32)
    }

    /// The chart as SVG text, `size` pixels (width, height).
    pub fn svg(&self, size: (u32, u32)) -> Result<String, ChartError> {
        check_size(size)?;
        let mut s = String::new();
        let frame = {
            let root = SVGBackend::with_string(&mut s, size).into_drawing_area();
            draw(self, &root)?
        };
        let comment = format!("\n{}", frame.comment());
        let at = s
            .find("<svg")
            .and_then(|i| s[i..].find('>').map(|j| i + j + 1))
            .ok_or_else(|| ChartError::Draw("plotters wrote no <svg> tag".into()))?;
        s.insert_str(at, &comment);
        Ok(s)
    }

    /// The chart as a PNG image, `size` pixels (width, height).
    pub fn png_bytes(&self, size: (u32, u32)) -> Result<Vec<u8>, ChartError> {
        check_size(size)?;
        let mut rgb = vec![0u8; size.0 as usize * size.1 as usize * 3];
        {
            let root = Raster(BitMapBackend::with_buffer(&mut rgb, size)).into_drawing_area();
            draw(self, &root)?;
        }
        let mut out = Vec::new();
        image::ImageEncoder::write_image(
            image::codecs::png::PngEncoder::new(&mut out),
            &rgb,
            size.0,
            size.1,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|e| ChartError::Draw(format!("encoding the PNG: {e}")))?;
        Ok(out)
    }

    /// Writes the chart as a PNG image to `path`.
    pub fn png(&self, path: &Path, size: (u32, u32)) -> Result<(), ChartError> {
        let bytes = self.png_bytes(size)?;
        std::fs::write(path, bytes)
            .map_err(|e| ChartError::Write { file: path.display().to_string(), msg: e.to_string() })
    }

    /// The chart in `format`, as bytes to write.
    pub fn render(&self, format: Format, size: (u32, u32)) -> Result<Vec<u8>, ChartError> {
        match format {
            Format::Svg => self.svg(size).map(String::into_bytes),
            Format::Png => self.png_bytes(size),
        }
    }
}

fn check_size((w, h): (u32, u32)) -> Result<(), ChartError> {
    if !(320..=8000).contains(&w) || !(240..=8000).contains(&h) {
        return Err(ChartError::Size(w, h));
    }
    Ok(())
}

// ---------------------------------------------------------------- layout

const MARGIN: i32 = 14;
// text sizes as plotters counts them: the line height; the em is 1/1.24 of it
// (the SVG backend writes `font-size` = size / 1.24)
const TITLE_SIZE: f64 = 22.0;
const LEGEND_SIZE: f64 = 17.0;
const TICK_SIZE: f64 = 16.0;
const DESC_SIZE: f64 = 18.0;
/// The longest group label stood on end, in pixels; longer ones are shortened.
const MAX_LABEL: f64 = 320.0;

/// Text of plotters size `size` (em = size / 1.24) as ab_glyph's scale (the height from descender to ascender).
fn px_scale(size: f64) -> PxScale {
    let f = &*FONT;
    PxScale::from((size / 1.24) as f32 * f.height_unscaled() / f.units_per_em().unwrap_or(2048.0))
}

/// The width of `text` at plotters size `size`, in pixels (DejaVu Sans' metrics).
fn text_width(text: &str, size: f64) -> f64 {
    let f = FONT.as_scaled(px_scale(size));
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            w += f.kern(p, id);
        }
        w += f.h_advance(id);
        prev = Some(id);
    }
    f64::from(w)
}

/// `text` broken into lines no wider than `width` (at `\n` and between words).
fn wrap(text: &str, size: f64, width: f64) -> Vec<String> {
    let mut lines = Vec::new();
    for para in text.split('\n') {
        let mut line = String::new();
        for word in para.split_whitespace() {
            let candidate = if line.is_empty() { word.to_string() } else { format!("{line} {word}") };
            if !line.is_empty() && text_width(&candidate, size) > width {
                lines.push(std::mem::take(&mut line));
                line = word.to_string();
            } else {
                line = candidate;
            }
        }
        lines.push(line);
    }
    lines
}

/// `text` shortened with an ellipsis to at most `width` pixels.
fn shorten(text: &str, size: f64, width: f64) -> String {
    if text_width(text, size) <= width {
        return text.to_string();
    }
    let mut s: String = text.to_string();
    while !s.is_empty() && text_width(&format!("{s}…"), size) > width {
        s.pop();
    }
    format!("{}…", s.trim_end())
}

fn colour(i: usize) -> RGBColor {
    let (r, g, b) = PALETTE[i % PALETTE.len()];
    RGBColor(r, g, b)
}

fn band_colour() -> RGBAColor {
    RGBColor(BAND_COLOUR.0, BAND_COLOUR.1, BAND_COLOUR.2).mix(BAND_OPACITY)
}

fn font(size: f64) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", size).into_font()).color(&BLACK)
}

// ---------------------------------------------------------------- axes

/// One axis: its range, scale and ticks (all in data units).
#[derive(Debug, Clone)]
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
    ticks: Vec<f64>,
    /// The tick spacing of a linear axis (for the labels' decimals).
    step: f64,
}

/// 1, 2 or 5 times a power of ten, near `span / target`.
fn nice_step(span: f64, target: f64) -> f64 {
    let raw = span / target;
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    let m = if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

/// `v` with float noise removed (12 significant digits).
fn clean(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

impl Axis {
    /// A linear axis over `min..max`: `zero` takes 0 in, `pad` widens by a
    /// fraction of the span (not past zero when it is an end), `integer` keeps
    /// ticks on whole numbers.
    fn linear(min: f64, max: f64, zero: bool, pad: f64, integer: bool) -> Axis {
        let (mut lo, mut hi) = (min, max);
        if zero {
            lo = lo.min(0.0);
            hi = hi.max(0.0);
        }
        if hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1.0) {
            let d = if lo.abs() > 0.0 { lo.abs() * 0.1 } else { 1.0 };
            if !(zero && lo == 0.0) {
                lo -= d;
            }
            hi += d;
        }
        let span = hi - lo;
        if !(zero && lo == 0.0) {
            lo -= pad * span;
        }
        if !(zero && hi == 0.0) {
            hi += pad * span;
        }
        let mut step = nice_step(hi - lo, 6.0);
        if integer {
            step = step.max(1.0);
        }
        let ticks = ((lo / step).ceil() as i64..=(hi / step).floor() as i64).map(|k| clean(k as f64 * step)).collect();
        Axis { lo, hi, log: false, ticks, step }
    }

    /// A logarithmic axis over `min..max` (both positive), widened by 5 % of its decades.
    fn log(min: f64, max: f64) -> Axis {
        let (mut a, mut b) = (min.log10(), max.log10());
        if b - a < 1e-9 {
            a -= 0.5;
            b += 0.5;
        }
        let pad = 0.05 * (b - a);
        a -= pad;
        b += pad;
        let (lo, hi) = (10f64.powf(a), 10f64.powf(b));
        let decades = b - a;
        let pow = |m: f64, k: i64| -> f64 { format!("{m}e{k}").parse().unwrap_or(m * 10f64.powi(k as i32)) };
        let ticks: Vec<f64> = if decades >= 4.0 {
            let every = (decades / 8.0).ceil().max(1.0) as i64;
            (a.ceil() as i64..=b.floor() as i64).filter(|k| k.rem_euclid(every) == 0).map(|k| pow(1.0, k)).collect()
        } else if decades >= 0.7 {
            (a.floor() as i64..=b.ceil() as i64)
                .flat_map(|k| [1.0, 2.0, 5.0].map(|m| pow(m, k)))
                .filter(|v| (lo..=hi).contains(v))
                .collect()
        } else {
            let step = nice_step(hi - lo, 5.0);
            ((lo / step).ceil() as i64..=(hi / step).floor() as i64)
                .map(|k| clean(k as f64 * step))
                .filter(|v| *v > 0.0)
                .collect()
        };
        Axis { lo, hi, log: true, ticks, step: 0.0 }
    }

    /// `v` in axis space (its logarithm on a log axis).
    fn t(&self, v: f64) -> f64 {
        if self.log { v.log10() } else { v }
    }

    /// The label of the tick at axis-space `t`.
    fn label(&self, t: f64) -> String {
        if self.log {
            let v = clean(10f64.powf(t));
            if !(1e-4..1e6).contains(&v.abs()) { format!("{v:e}") } else { format!("{v}") }
        } else {
            let v = if t.abs() < self.step * 1e-9 { 0.0 } else { t };
            if v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
                return format!("{v:e}");
            }
            let decimals = (-(self.step.log10() + 1e-9).floor()).max(0.0) as usize;
            format!("{v:.decimals$}")
        }
    }
}

/// A linear coordinate (in axis space) with our ticks for plotters' mesh.
struct Ticked {
    inner: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for Ticked {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() { Vec::new() } else { self.ticks.clone() }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

impl ValueFormatter<f64> for Ticked {
    fn format(value: &f64) -> String {
        format!("{value}")
    }
}

/// How values map to pixels: the ends of the plot area and of the ranges.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// What was drawn: `bars`, `lines` or `scatter`.
    pub kind: &'static str,
    /// Pixel columns of the x range's low and high end.
    pub x_pixels: (i32, i32),
    /// Pixel rows of the y range's low and high end.
    pub y_pixels: (i32, i32),
    /// The x range (data units).
    pub x_range: (f64, f64),
    /// The y range (data units).
    pub y_range: (f64, f64),
    /// Whether x is on a log scale.
    pub log_x: bool,
    /// Whether y is on a log scale.
    pub log_y: bool,
}

fn to_pixel(v: f64, (lo, hi): (f64, f64), (p0, p1): (i32, i32), log: bool) -> f64 {
    let (t, tlo, thi) = if log { (v.log10(), lo.log10(), hi.log10()) } else { (v, lo, hi) };
    f64::from(p0) + (t - tlo) / (thi - tlo) * f64::from(p1 - p0)
}

impl Frame {
    /// The pixel column of x value `v` (unrounded).
    pub fn x(&self, v: f64) -> f64 {
        to_pixel(v, self.x_range, self.x_pixels, self.log_x)
    }

    /// The pixel row of y value `v` (unrounded).
    pub fn y(&self, v: f64) -> f64 {
        to_pixel(v, self.y_range, self.y_pixels, self.log_y)
    }

    fn xi(&self, v: f64) -> i32 {
        self.x(v).round() as i32
    }

    fn yi(&self, v: f64) -> i32 {
        self.y(v).round() as i32
    }

    /// The comment the SVG carries (see the module's documentation).
    pub fn comment(&self) -> String {
        let scale = |log| if log { "log" } else { "linear" };
        format!(
            "<!-- warplight-chart kind={} x-pixels={},{} y-pixels={},{} x-range={},{} y-range={},{} x-scale={} y-scale={} -->",
            self.kind,
            self.x_pixels.0,
            self.x_pixels.1,
            self.y_pixels.0,
            self.y_pixels.1,
            self.x_range.0,
            self.x_range.1,
            self.y_range.0,
            self.y_range.1,
            scale(self.log_x),
            scale(self.log_y)
        )
    }
}

// ---------------------------------------------------------------- checks

fn finite(name: &str, what: &str, v: f64) -> Result<(), ChartError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(ChartError::Data(format!("{name}: {what} is {v}, which a chart cannot show")))
    }
}

fn check_bars(b: &Bars) -> Result<(), ChartError> {
    if b.groups.is_empty() || b.series.is_empty() {
        return Err(ChartError::Empty(format!("{}: no groups or no series", b.title)));
    }
    for s in &b.series {
        if s.values.len() != b.groups.len() {
            return Err(ChartError::Data(format!(
                "series `{}` has {} values for {} groups",
                s.name,
                s.values.len(),
                b.groups.len()
            )));
        }
        for (g, v) in b.groups.iter().zip(&s.values) {
            if let Some(v) = v {
                finite(&s.name, g, *v)?;
            }
        }
    }
    if !b.bands.is_empty() && b.bands.len() != b.groups.len() {
        return Err(ChartError::Data(format!("{} bands for {} groups", b.bands.len(), b.groups.len())));
    }
    for (g, band) in b.groups.iter().zip(&b.bands) {
        if let Some((lo, hi)) = band {
            finite("band", g, *lo)?;
            finite("band", g, *hi)?;
            if lo > hi {
                return Err(ChartError::Data(format!("band of {g}: low end {lo} above high end {hi}")));
            }
        }
    }
    if b.series.iter().all(|s| s.values.iter().all(Option::is_none)) {
        return Err(ChartError::Empty(format!("{}: every value is missing", b.title)));
    }
    Ok(())
}

fn check_points(title: &str, series: &[Series], log_x: bool, log_y: bool) -> Result<(), ChartError> {
    if series.iter().all(|s| s.points.is_empty()) {
        return Err(ChartError::Empty(format!("{title}: no points")));
    }
    for s in series {
        for (i, &(x, y)) in s.points.iter().enumerate() {
            finite(&s.name, &format!("x of point {i}"), x)?;
            finite(&s.name, &format!("y of point {i}"), y)?;
            for (log, axis, v) in [(log_x, "x", x), (log_y, "y", y)] {
                if log && v <= 0.0 {
                    return Err(ChartError::Data(format!(
                        "{}: point {i} has {axis} = {v}, which a logarithmic axis cannot show",
                        s.name
                    )));
                }
            }
        }
    }
    Ok(())
}

fn extent(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

// ---------------------------------------------------------------- drawing

fn de<E: std::error::Error + Send + Sync>(e: DrawingAreaErrorKind<E>) -> ChartError {
    ChartError::Draw(e.to_string())
}

/// What a legend entry shows beside its name.
#[derive(Clone, Copy)]
enum Swatch {
    Box(RGBColor),
    Band,
    Line(RGBColor, bool),
    Dot(RGBColor),
}

/// Everything the three kinds share: title, legend, axes; returns the frame.
struct Plan<'a> {
    kind: &'static str,
    title: &'a str,
    legend: Vec<(Swatch, &'a str)>,
    x: Axis,
    y: Axis,
    x_label: &'a str,
    y_label: &'a str,
    /// Group labels under the x axis (bars) instead of ticks.
    groups: Option<&'a [String]>,
}

fn draw<DB: DrawingBackend>(chart: &Chart, root: &DrawingArea<DB, Shift>) -> Result<Frame, ChartError> {
    match chart {
        Chart::Bars(b) => draw_bars(b, root),
        Chart::Lines(l) => draw_lines(l, root),
        Chart::Scatter(s) => draw_scatter(s, root),
    }
}

fn draw_frame<DB: DrawingBackend>(plan: &Plan, root: &DrawingArea<DB, Shift>) -> Result<Frame, ChartError> {
    root.fill(&WHITE).map_err(de)?;
    let (w, h) = root.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let mut y = MARGIN;
    for line in wrap(plan.title, TITLE_SIZE, f64::from(w - 2 * MARGIN)) {
        let style = font(TITLE_SIZE).pos(Pos::new(HPos::Center, VPos::Top));
        root.draw(&Text::new(line, (w / 2, y), style)).map_err(de)?;
        y += (TITLE_SIZE * 1.35).round() as i32;
    }
    y += 4;
    // legend: rows of (swatch, name), centred
    let items: Vec<(Swatch, &str, i32)> =
        plan.legend.iter().map(|&(s, n)| (s, n, 24 + text_width(n, LEGEND_SIZE).ceil() as i32)).collect();
    let mut rows: Vec<Vec<(Swatch, &str, i32)>> = vec![Vec::new()];
    let mut row_w = 0;
    for it in items {
        let last = rows.last_mut().expect("rows start non-empty");
        if !last.is_empty() && row_w + 20 + it.2 > w - 2 * MARGIN {
            rows.push(vec![it]);
            row_w = it.2;
        } else {
            row_w += if last.is_empty() { it.2 } else { 20 + it.2 };
            last.push(it);
        }
    }
    for row in rows.iter().filter(|r| !r.is_empty()) {
        let total: i32 = row.iter().map(|it| it.2).sum::<i32>() + 20 * (row.len() as i32 - 1);
        let mut x = (w - total) / 2;
        for &(swatch, name, width) in row {
            let mid = y + 9;
            match swatch {
                Swatch::Box(c) => root.draw(&Rectangle::new([(x, mid - 6), (x + 16, mid + 6)], c.filled())),
                Swatch::Band => root.draw(&Rectangle::new([(x, mid - 7), (x + 16, mid + 7)], band_colour().filled())),
                Swatch::Line(c, dot) => {
                    root.draw(&PathElement::new(vec![(x, mid), (x + 16, mid)], Color::stroke_width(&c, 2)))
                        .map_err(de)?;
                    if dot { root.draw(&Circle::new((x + 8, mid), 3, c.filled())) } else { Ok(()) }
                }
                Swatch::Dot(c) => root.draw(&Circle::new((x + 8, mid), 4, c.filled())),
            }
            .map_err(de)?;
            let style = font(LEGEND_SIZE).pos(Pos::new(HPos::Left, VPos::Center));
            root.draw(&Text::new(name.to_string(), (x + 22, mid), style)).map_err(de)?;
            x += width + 20;
        }
        y += 20;
    }
    y += 8;

    // label areas: tick labels and the axis descriptions
    let y_ticks_w = plan.y.ticks.iter().map(|&v| text_width(&plan.y.label(plan.y.t(v)), TICK_SIZE)).fold(0.0, f64::max);
    let y_area = y_ticks_w.ceil() as i32 + 14 + if plan.y_label.is_empty() { 0 } else { 26 };
    let mut group_labels: Vec<String> = Vec::new();
    let mut stand = false;
    let x_area = if let Some(groups) = plan.groups {
        let plot_w = f64::from(w - 2 * MARGIN - 10 - y_area);
        let slot = plot_w / groups.len().max(1) as f64;
        let widest = groups.iter().map(|g| text_width(g, TICK_SIZE)).fold(0.0, f64::max);
        stand = widest > slot - 6.0;
        if stand {
            let room = MAX_LABEL.min(f64::from(h) * 0.45);
            group_labels = groups.iter().map(|g| shorten(g, TICK_SIZE, room)).collect();
            let widest = group_labels.iter().map(|g| text_width(g, TICK_SIZE)).fold(0.0, f64::max);
            widest.ceil() as i32 + 14
        } else {
            group_labels = groups.to_vec();
            28
        }
    } else {
        14 + 8 + if plan.x_label.is_empty() { 0 } else { 26 }
    };
    let area = root.margin(y, MARGIN, MARGIN, MARGIN + 10);
    let (xs, ys) = (&plan.x, &plan.y);
    let x_keys = if plan.groups.is_some() { Vec::new() } else { xs.ticks.iter().map(|&v| xs.t(v)).collect() };
    let y_keys = ys.ticks.iter().map(|&v| ys.t(v)).collect();
    let mut ctx = ChartBuilder::on(&area)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(
            Ticked { inner: (xs.t(xs.lo)..xs.t(xs.hi)).into(), ticks: x_keys },
            Ticked { inner: (ys.t(ys.lo)..ys.t(ys.hi)).into(), ticks: y_keys },
        )
        .map_err(de)?;
    let x_fmt = |t: &f64| xs.label(*t);
    let y_fmt = |t: &f64| ys.label(*t);
    let grid = RGBColor(0, 0, 0).mix(0.12);
    let mut mesh = ctx.configure_mesh();
    mesh.label_style(font(TICK_SIZE))
        .axis_desc_style(font(DESC_SIZE))
        .bold_line_style(grid)
        .light_line_style(TRANSPARENT)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt);
    if !plan.x_label.is_empty() {
        mesh.x_desc(plan.x_label);
    }
    if !plan.y_label.is_empty() {
        mesh.y_desc(plan.y_label);
    }
    if plan.groups.is_some() {
        mesh.disable_x_mesh();
    }
    mesh.draw().map_err(de)?;
    let (px, py) = ctx.plotting_area().get_pixel_range();
    let frame = Frame {
        kind: plan.kind,
        x_pixels: (px.start, px.end - 1),
        y_pixels: (py.end - 1, py.start),
        x_range: (xs.lo, xs.hi),
        y_range: (ys.lo, ys.hi),
        log_x: xs.log,
        log_y: ys.log,
    };
    // group labels, centred under their slots (on end when they do not fit)
    for (i, g) in group_labels.into_iter().enumerate() {
        let cx = frame.xi(i as f64 + 0.5);
        let top = frame.y_pixels.0 + 6;
        let style = if stand {
            font(TICK_SIZE).pos(Pos::new(HPos::Right, VPos::Center)).transform(FontTransform::Rotate270)
        } else {
            font(TICK_SIZE).pos(Pos::new(HPos::Center, VPos::Top))
        };
        root.draw(&Text::new(g, (cx, top), style)).map_err(de)?;
    }
    Ok(frame)
}

fn draw_bars<DB: DrawingBackend>(b: &Bars, root: &DrawingArea<DB, Shift>) -> Result<Frame, ChartError> {
    check_bars(b)?;
    let values = b.series.iter().flat_map(|s| s.values.iter().flatten().copied());
    let bands = b.bands.iter().flatten().flat_map(|&(lo, hi)| [lo, hi]);
    let (lo, hi) = extent(values.chain(bands));
    let n = b.groups.len();
    let mut legend: Vec<(Swatch, &str)> =
        b.series.iter().enumerate().map(|(k, s)| (Swatch::Box(colour(k)), s.name.as_str())).collect();
    if b.bands.iter().any(Option::is_some) {
        legend.push((Swatch::Band, if b.band_label.is_empty() { "band" } else { &b.band_label }));
    }
    let plan = Plan {
        kind: "bars",
        title: &b.title,
        legend,
        x: Axis { lo: 0.0, hi: n as f64, log: false, ticks: Vec::new(), step: 1.0 },
        y: Axis::linear(lo, hi, true, 0.04, false),
        x_label: "",
        y_label: &b.y_label,
        groups: Some(&b.groups),
    };
    let f = draw_frame(&plan, root)?;
    let zero = f.yi(0.0);
    for i in 0..n {
        let (left, right) = (f.x(i as f64), f.x(i as f64 + 1.0));
        let slot = right - left;
        if let Some(Some((lo, hi))) = b.bands.get(i) {
            let (x0, x1) = ((left + 0.04 * slot).round() as i32, (right - 0.04 * slot).round() as i32);
            root.draw(&Rectangle::new([(x0, f.yi(*hi)), (x1, f.yi(*lo))], band_colour().filled())).map_err(de)?;
        }
        let inner = 0.7 * slot;
        let bw = inner / b.series.len() as f64;
        for (k, s) in b.series.iter().enumerate() {
            let Some(v) = s.values[i] else { continue };
            let x0 = (left + 0.15 * slot + k as f64 * bw).round() as i32;
            let x1 = ((left + 0.15 * slot + (k + 1) as f64 * bw).round() as i32 - 1).max(x0 + 1);
            let yv = f.yi(v);
            root.draw(&Rectangle::new([(x0, yv.min(zero)), (x1, yv.max(zero))], colour(k).filled())).map_err(de)?;
        }
    }
    root.draw(&PathElement::new(vec![(f.x_pixels.0, zero), (f.x_pixels.1, zero)], Color::stroke_width(&BLACK, 1)))
        .map_err(de)?;
    root.present().map_err(de)?;
    Ok(f)
}

fn draw_points<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    f: &Frame,
    series: &[Series],
    join: bool,
    radius: u32,
) -> Result<(), ChartError> {
    for (k, s) in series.iter().enumerate() {
        let px: Vec<BackendCoord> = s.points.iter().map(|&(x, y)| (f.xi(x), f.yi(y))).collect();
        if join && px.len() > 1 {
            root.draw(&PathElement::new(px.clone(), Color::stroke_width(&colour(k), 2))).map_err(de)?;
        }
        for p in px {
            root.draw(&Circle::new(p, radius, colour(k).filled())).map_err(de)?;
        }
    }
    Ok(())
}

fn draw_lines<DB: DrawingBackend>(l: &Lines, root: &DrawingArea<DB, Shift>) -> Result<Frame, ChartError> {
    check_points(&l.title, &l.series, false, false)?;
    let all = || l.series.iter().flat_map(|s| s.points.iter().copied());
    let (x0, x1) = extent(all().map(|p| p.0));
    let (y0, y1) = extent(all().map(|p| p.1));
    let integer = all().all(|p| p.0.fract() == 0.0);
    let plan = Plan {
        kind: "lines",
        title: &l.title,
        legend: l.series.iter().enumerate().map(|(k, s)| (Swatch::Line(colour(k), true), s.name.as_str())).collect(),
        x: Axis::linear(x0, x1, false, 0.02, integer),
        y: Axis::linear(y0, y1, true, 0.05, false),
        x_label: &l.x_label,
        y_label: &l.y_label,
        groups: None,
    };
    let f = draw_frame(&plan, root)?;
    draw_points(root, &f, &l.series, true, 3)?;
    root.present().map_err(de)?;
    Ok(f)
}

fn draw_scatter<DB: DrawingBackend>(s: &Scatter, root: &DrawingArea<DB, Shift>) -> Result<Frame, ChartError> {
    check_points(&s.title, &s.series, s.log_x, s.log_y)?;
    let all = || s.series.iter().flat_map(|s| s.points.iter().copied());
    let (x0, x1) = extent(all().map(|p| p.0));
    let (y0, y1) = extent(all().map(|p| p.1));
    let axis = |lo, hi, log| if log { Axis::log(lo, hi) } else { Axis::linear(lo, hi, false, 0.05, false) };
    let swatch = |k| if s.connect { Swatch::Line(colour(k), true) } else { Swatch::Dot(colour(k)) };
    let plan = Plan {
        kind: "scatter",
        title: &s.title,
        legend: s.series.iter().enumerate().map(|(k, se)| (swatch(k), se.name.as_str())).collect(),
        x: axis(x0, x1, s.log_x),
        y: axis(y0, y1, s.log_y),
        x_label: &s.x_label,
        y_label: &s.y_label,
        groups: None,
    };
    let f = draw_frame(&plan, root)?;
    draw_points(root, &f, &s.series, s.connect, 4)?;
    root.present().map_err(de)?;
    Ok(f)
}

// ---------------------------------------------------------------- PNG text

/// The bitmap backend with text drawn in the embedded DejaVu Sans. (plotters'
/// own font support is a crate-wide feature: turning it on would make every
/// other plotters user in the build — criterion's reports — fail for want of a
/// registered font.)
struct Raster<'a>(BitMapBackend<'a>);

type RasterError<'a> = DrawingErrorKind<<BitMapBackend<'a> as DrawingBackend>::ErrorType>;

impl<'a> DrawingBackend for Raster<'a> {
    type ErrorType = <BitMapBackend<'a> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.0.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), RasterError<'a>> {
        self.0.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), RasterError<'a>> {
        self.0.present()
    }

    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), RasterError<'a>> {
        self.0.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), RasterError<'a>> {
        self.0.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), RasterError<'a>> {
        self.0.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), RasterError<'a>> {
        self.0.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), RasterError<'a>> {
        self.0.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), RasterError<'a>> {
        self.0.fill_polygon(vert, style)
    }

    fn blit_bitmap(&mut self, pos: BackendCoord, size: (u32, u32), src: &[u8]) -> Result<(), RasterError<'a>> {
        self.0.blit_bitmap(pos, size, src)
    }

    /// Glyph coverage blended pixel by pixel; anchors as the SVG backend places
    /// them (baseline 0.76 em below a top anchor, 0.27 em below a centre one,
    /// 0.27 em above a bottom one).
    fn draw_text<T: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &T,
        pos: BackendCoord,
    ) -> Result<(), RasterError<'a>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let size = style.size();
        let scale = px_scale(size);
        let f = FONT.as_scaled(scale);
        let width = text_width(text, size) as f32;
        let anchor = style.anchor();
        let dx = match anchor.h_pos {
            HPos::Left => 0.0,
            HPos::Center => -width / 2.0,
            HPos::Right => -width,
        };
        let baseline = (size / 1.24) as f32
            * match anchor.v_pos {
                VPos::Top => 0.76,
                VPos::Center => 0.27,
                VPos::Bottom => -0.27,
            };
        let trans = style.transform();
        let (w, h) = self.get_size();
        let mut caret = 0.0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = f.glyph_id(c);
            if let Some(p) = prev {
                caret += f.kern(p, id);
            }
            prev = Some(id);
            let glyph = id.with_scale_and_position(scale, point(dx + caret, baseline));
            caret += f.h_advance(id);
            let Some(outline) = FONT.outline_glyph(glyph) else { continue };
            let b = outline.px_bounds();
            let mut pixels = Vec::new();
            outline.draw(|x, y, cov| pixels.push((b.min.x as i32 + x as i32, b.min.y as i32 + y as i32, cov)));
            for (x, y, cov) in pixels {
                if cov <= 0.0 {
                    continue;
                }
                let (tx, ty) = trans.transform(x, y);
                let (sx, sy) = (pos.0 + tx, pos.1 + ty);
                if sx >= 0 && sy >= 0 && (sx as u32) < w && (sy as u32) < h {
                    let alpha = color.alpha * f64::from(cov.min(1.0));
                    self.0.draw_pixel((sx, sy), BackendColor { alpha, rgb: color.rgb })?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_linear_axes() {
        let a = Axis::linear(3.0, 100.0, true, 0.0, false);
        assert_eq!((a.lo, a.hi), (0.0, 100.0));
        assert_eq!(a.ticks, vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0]);
        let p = Axis::linear(3.0, 97.0, true, 0.05, false);
        assert_eq!((p.lo, p.ticks.len()), (0.0, 6));
        assert!((p.hi - 101.85).abs() < 1e-9, "{p:?}");
        assert_eq!(a.label(40.0), "40");
        let b = Axis::linear(-12.5, 0.3, true, 0.0, false);
        assert!(b.lo <= -12.5 && b.hi >= 0.3 && b.ticks.contains(&0.0), "{b:?}");
        let c = Axis::linear(0.1, 0.7, false, 0.0, false);
        assert_eq!(c.label(0.1 + 0.2), "0.3");
        let one = Axis::linear(5.0, 5.0, false, 0.0, true);
        assert!(one.lo < 5.0 && one.hi > 5.0 && one.ticks.iter().all(|t| t.fract() == 0.0), "{one:?}");
    }

    #[test]
    fn log_axes_tick_decades_or_one_two_five() {
        let a = Axis::log(1e-4, 1.0);
        assert_eq!(a.ticks, vec![1e-4, 1e-3, 1e-2, 1e-1, 1.0]);
        assert_eq!(a.label(a.t(1e-3)), "0.001");
        assert_eq!(a.label(a.t(1e-5)), "1e-5");
        let b = Axis::log(1.5, 30.0);
        assert_eq!(b.ticks, vec![2.0, 5.0, 10.0, 20.0]);
    }

    #[test]
    fn formats_follow_the_extension() {
        assert_eq!(Format::of(Path::new("a/b.SVG")).unwrap(), Format::Svg);
        assert_eq!(Format::of(Path::new("b.png")).unwrap(), Format::Png);
        let e = Format::of(Path::new("b.jpg")).unwrap_err().to_string();
        assert_eq!(e, "b.jpg: charts are written as .svg or .png, not .jpg");
        assert!(Format::of(Path::new("b")).unwrap_err().to_string().contains("no extension"));
    }

    #[test]
    fn wrapping_and_shortening() {
        let lines = wrap("a long title that will not fit\nsecond", 18.0, 120.0);
        assert!(lines.len() >= 3 && lines.last().unwrap() == "second", "{lines:?}");
        let s = shorten("scene6 / push-down + short-stack", 13.0, 60.0);
        assert!(s.ends_with('…') && text_width(&s, 13.0) <= 60.0, "{s}");
    }
}
