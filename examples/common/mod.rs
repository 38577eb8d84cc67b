//! Shared plumbing of the examples: command-line parsing, output directory, PNG writing and charts.
//!
//! Each example's body lives in a module here (`lobes`, `pndf_images`, …) exposing
//! `pub fn run(out: &Path, quick: bool) -> Result<Vec<Artifact>, Box<dyn Error>>`, so that the thin
//! `examples/<name>.rs` mains and the `gallery` run the same code.
#![allow(dead_code)]

pub mod compare;
pub mod curves;
pub mod energy;
pub mod energy_glint;
pub mod grazing;
pub mod lobes;
pub mod material;
pub mod mixture_images;
pub mod normal_mapping;
pub mod orb;
pub mod orb_curves;
pub mod pndf_images;
pub mod procedural;
pub mod quadrature;
pub mod render;
pub mod shading_points;

use plotters::prelude::*;
use std::error::Error;
use std::path::{Path, PathBuf};

/// Default output directory, relative to the crate root.
pub const DEFAULT_OUT: &str = "target/brdf-out";

/// One file an example wrote, with one line saying what it shows (the gallery's index uses it).
#[derive(Clone, Debug)]
pub struct Artifact {
    /// Path of the file.
    pub path: PathBuf,
    /// One line of explanation.
    pub caption: String,
}

impl Artifact {
    /// A new artifact.
    pub fn new(path: impl Into<PathBuf>, caption: impl Into<String>) -> Artifact {
        Artifact {
            path: path.into(),
            caption: caption.into(),
        }
    }
}

/// Result type of example bodies.
pub type Res<T> = Result<T, Box<dyn Error>>;

/// The value following `--name` on the command line, if any.
pub fn arg_value(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
}

/// Whether `--name` is on the command line.
pub fn has_flag(name: &str) -> bool {
    std::env::args().any(|a| a == name)
}

/// The output directory (`--out DIR`, default [`DEFAULT_OUT`]), created if needed.
pub fn out_dir() -> Res<PathBuf> {
    let dir = PathBuf::from(arg_value("--out").unwrap_or_else(|| DEFAULT_OUT.to_string()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Registers the embedded DejaVu font as "sans-serif" for plotters (once; later calls are no-ops).
pub fn register_font() {
    use std::sync::Once;
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Saves an 8-bit RGB buffer (row major, 3 bytes per pixel) as PNG.
pub fn save_rgb(path: &Path, width: u32, height: u32, rgb: Vec<u8>) -> Res<()> {
    let img = image::RgbImage::from_raw(width, height, rgb).ok_or("buffer size does not match")?;
    img.save(path)?;
    Ok(())
}

/// A perceptually ordered colour map (viridis-like, 5 control points), t ∈ [0, 1].
pub fn colormap(t: f32) -> [u8; 3] {
    const C: [[f32; 3]; 5] = [
        [0.267, 0.005, 0.329],
        [0.230, 0.322, 0.546],
        [0.128, 0.567, 0.551],
        [0.369, 0.789, 0.383],
        [0.993, 0.906, 0.144],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    } * 4.0;
    let i = (t as usize).min(3);
    let f = t - i as f32;
    let mut out = [0u8; 3];
    for k in 0..3 {
        out[k] = ((C[i][k] * (1.0 - f) + C[i + 1][k] * f) * 255.0).round() as u8;
    }
    out
}

/// Writes a false-colour image of `values` (row major, `width` × `height`), mapped linearly from
/// [0, max] (max = the largest finite value when `max` is `None`). Non-finite values are black.
pub fn save_heatmap(
    path: &Path,
    width: u32,
    height: u32,
    values: &[f32],
    max: Option<f32>,
) -> Res<()> {
    let m = max.unwrap_or_else(|| {
        values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f32, f32::max)
    });
    let scale = if m > 0.0 { 1.0 / m } else { 0.0 };
    let mut rgb = Vec::with_capacity(values.len() * 3);
    for &v in values {
        if v.is_finite() {
            rgb.extend_from_slice(&colormap(v * scale));
        } else {
            rgb.extend_from_slice(&[0, 0, 0]);
        }
    }
    save_rgb(path, width, height, rgb)
}

/// One named series of a line chart.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points, drawn in order.
    pub points: Vec<(f64, f64)>,
    /// Half-widths of an error bar per point (drawn from y − e to y + e); empty: no bars.
    pub errors: Vec<f64>,
}

impl Series {
    /// A series from a label and points.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            points,
            errors: Vec::new(),
        }
    }

    /// The series with an error bar of half-width `errors[k]` at point k.
    pub fn with_errors(mut self, errors: Vec<f64>) -> Series {
        self.errors = errors;
        self
    }
}

/// Axis scale of a chart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear axis.
    Linear,
    /// Base-10 logarithmic axis (non-positive values are dropped).
    Log,
}

/// Options of [`line_chart`].
pub struct Chart<'a> {
    /// Title at the top.
    pub title: &'a str,
    /// Label of the x axis.
    pub x_label: &'a str,
    /// Label of the y axis.
    pub y_label: &'a str,
    /// Scale of the x axis.
    pub x_scale: Scale,
    /// Scale of the y axis.
    pub y_scale: Scale,
    /// Draw markers at the points as well as lines.
    pub markers: bool,
    /// Draw points only (a scatter plot).
    pub scatter: bool,
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Fixed y range (e.g. a floor for log plots of functions that underflow); `None` fits the data.
    pub y_range: Option<(f64, f64)>,
    /// Where the legend sits (default: middle right).
    pub legend: SeriesLabelPosition,
}

impl<'a> Chart<'a> {
    /// A linear line chart of 800 × 500 pixels.
    pub fn new(title: &'a str, x_label: &'a str, y_label: &'a str) -> Chart<'a> {
        Chart {
            title,
            x_label,
            y_label,
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            markers: false,
            scatter: false,
            size: (800, 500),
            y_range: None,
            legend: SeriesLabelPosition::MiddleRight,
        }
    }
}

fn range_of(values: impl Iterator<Item = f64>, scale: Scale) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (scale == Scale::Linear || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    match scale {
        Scale::Linear => {
            let pad = ((hi - lo) * 0.05).max(1e-9);
            (lo - pad, hi + pad)
        }
        Scale::Log => (lo / 1.5, hi * 1.5),
    }
}

/// Draws a line (or scatter) chart of several series to a PNG file.
pub fn line_chart(path: &Path, chart: &Chart, series: &[Series]) -> Res<()> {
    register_font();
    let (w, h) = chart.size;
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let keep = |v: f64, s: Scale| v.is_finite() && (s == Scale::Linear || v > 0.0);
        let (x0, x1) = range_of(
            series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
            chart.x_scale,
        );
        let (y0, y1) = chart.y_range.unwrap_or_else(|| {
            range_of(
                series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
                chart.y_scale,
            )
        });
        let keep_y = |v: f64| keep(v, chart.y_scale) && v >= y0.min(y1) && v <= y0.max(y1);
        let y_fmt = |v: &f64| match chart.y_scale {
            Scale::Log => format!("{v:.0e}"),
            Scale::Linear => format!("{v:.3}"),
        };
        macro_rules! draw {
            ($ctx:expr) => {{
                let mut ctx = $ctx;
                ctx.configure_mesh()
                    .x_desc(chart.x_label)
                    .y_desc(chart.y_label)
                    .y_label_formatter(&y_fmt)
                    .draw()?;
                for (i, s) in series.iter().enumerate() {
                    let color = Palette99::pick(i).to_rgba();
                    let pts: Vec<(f64, f64)> = s
                        .points
                        .iter()
                        .copied()
                        .filter(|p| keep(p.0, chart.x_scale) && keep_y(p.1))
                        .collect();
                    if chart.scatter {
                        ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?
                            .label(s.label.clone())
                            .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled()));
                    } else {
                        ctx.draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))?
                            .label(s.label.clone())
                            .legend(move |(x, y)| {
                                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                            });
                        // Error bars, clipped to the y range.
                        let (lo, hi) = (y0.min(y1), y0.max(y1));
                        let bars: Vec<((f64, f64), (f64, f64))> = s
                            .points
                            .iter()
                            .zip(&s.errors)
                            .filter(|(p, e)| {
                                keep(p.0, chart.x_scale) && keep_y(p.1) && e.is_finite()
                            })
                            .map(|(p, e)| {
                                let top = (p.1 + e).min(hi);
                                let bottom = (p.1 - e).max(lo);
                                let bottom = if chart.y_scale == Scale::Log && bottom <= 0.0 {
                                    lo
                                } else {
                                    bottom
                                };
                                ((p.0, bottom), (p.0, top))
                            })
                            .collect();
                        ctx.draw_series(
                            bars.into_iter()
                                .map(|(a, b)| PathElement::new(vec![a, b], color.stroke_width(2))),
                        )?;
                        if chart.markers {
                            // A lone point (one method in a scatter-like chart) gets a big marker.
                            let r = if pts.len() == 1 { 7 } else { 3 };
                            ctx.draw_series(
                                pts.iter().map(|&p| Circle::new(p, r, color.filled())),
                            )?;
                        }
                    }
                }
                ctx.configure_series_labels()
                    .position(chart.legend.clone())
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()?;
            }};
        }
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(chart.title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(45)
            .y_label_area_size(70);
        match (chart.x_scale, chart.y_scale) {
            (Scale::Linear, Scale::Linear) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)?),
            (Scale::Log, Scale::Linear) => {
                draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)?)
            }
            (Scale::Linear, Scale::Log) => {
                draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())?)
            }
            (Scale::Log, Scale::Log) => {
                draw!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?)
            }
        }
        root.present()?;
    }
    save_rgb(path, w, h, buf)
}

/// A unit direction at polar angle `theta` (degrees) and azimuth 30° (off the tangent axes, so that
/// anisotropic lobes are seen obliquely), in the local shading frame.
pub fn view(theta: f64) -> brdf::Vec3 {
    let (t, p) = (theta.to_radians(), 30f64.to_radians());
    brdf::Vec3::new(
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    )
}

/// The k-th point of the R2 low-discrepancy sequence in [0, 1)².
pub fn r2(k: usize) -> brdf::Vec2 {
    let (a, b) = (0.754_877_7_f64, 0.569_840_3_f64);
    brdf::Vec2::new(
        (0.5 + a * k as f64).fract() as f32,
        (0.5 + b * k as f64).fract() as f32,
    )
}
