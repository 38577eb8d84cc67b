//! The chart of the orb's error-against-time sweep: log-log panels of error against time, maps ×
//! map scales, every glint model beside naive sampling.

use super::{CurveOptions, Point};
use crate::common::{Res, register_font, save_rgb};
use plotters::prelude::*;
use std::path::Path;

/// Width in pixels of the legend column of a one-column chart.
const LEGEND_WIDTH: u32 = 260;

/// A grid of log-log panels, maps × scales.
pub(super) fn chart(path: &Path, points: &[Point], opts: &CurveOptions, setting: &str) -> Res<()> {
    register_font();
    // The glint models, in first-seen order.
    let mut labels: Vec<String> = Vec::new();
    for p in points {
        if p.method != "naive" && !p.method.starts_with("(b)") && !labels.contains(&p.method) {
            labels.push(p.method.clone());
        }
    }
    let (cols, rows) = (opts.scales.len() as u32, opts.maps.len() as u32);
    let (pw, ph) = (360u32, 260u32);
    // At least two panels wide, so that the title fits (the preview has one column).
    let (w, h) = ((cols * pw).max(2 * pw), rows * ph + 30);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let (title, body) = root.split_vertically(30);
        title.draw(&Text::new(
            format!(
                "orb: denoised rel. RMSE vs (a) exact P-BRDF against time (s){}; naive dotted = vs (b)",
                match setting {
                    "full" => String::new(),
                    "quick" => ", --quick".to_string(),
                    other => format!(", {other}"),
                }
            ),
            (6, 6),
            ("sans-serif", 15).into_font(),
        ))?;
        // A one-column chart (the preview) is two panels wide: its legend goes into a column of its
        // own beside the panels, where it covers no point.
        let (plots, side) = if cols == 1 {
            let (p, s) = body.split_horizontally(w - LEGEND_WIDTH);
            (p, Some(s))
        } else {
            (body, None)
        };
        let panels = plots.split_evenly((rows as usize, cols as usize));
        let colours = [
            BLUE,
            RGBColor(120, 170, 255),
            RED,
            RGBColor(240, 150, 150),
            RGBColor(0, 150, 0),
            RGBColor(140, 210, 140),
        ];
        for (pi, area) in panels.iter().enumerate() {
            let (map, scale) = (
                opts.maps[pi / cols as usize],
                opts.scales[pi % cols as usize],
            );
            let here: Vec<&Point> = points
                .iter()
                .filter(|p| p.map == map && p.scale == scale)
                .collect();
            let floor = 1e-3;
            let y = |e: f64| e.max(floor);
            let ts: Vec<f64> = here
                .iter()
                .flat_map(|p| [p.render_s, p.render_s + p.build_s])
                .filter(|t| *t > 0.0)
                .collect();
            let (tmin, tmax) = ts
                .iter()
                .fold((f64::MAX, 0.0f64), |(a, b), &t| (a.min(t), b.max(t)));
            if ts.is_empty() {
                continue;
            }
            let tpp = here.first().map_or(0.0, |p| p.texels_per_pixel);
            let mut c = ChartBuilder::on(area)
                .caption(
                    format!("{map}, tiles {}x{scale}, ~{tpp:.0} texels/px", 2.0 * scale),
                    ("sans-serif", 13),
                )
                .margin(4)
                .x_label_area_size(22)
                .y_label_area_size(40)
                .build_cartesian_2d(
                    (tmin * 0.7..tmax * 1.4).log_scale(),
                    (floor..3.0f64).log_scale(),
                )?;
            c.configure_mesh()
                .x_labels(4)
                .y_labels(4)
                .label_style(("sans-serif", 10))
                .x_label_formatter(&|v| format!("{v:.0e}"))
                .y_label_formatter(&|v| format!("{v:.0e}"))
                .draw()?;
            let naive: Vec<&&Point> = here.iter().filter(|p| p.method == "naive").collect();
            c.draw_series(LineSeries::new(
                naive
                    .iter()
                    .map(|p| (p.render_s, y(p.vs_a.rel_rmse_denoised))),
                BLACK.stroke_width(2),
            ))?
            .label("naive")
            .legend(|(x, yy)| PathElement::new(vec![(x, yy), (x + 14, yy)], BLACK.stroke_width(2)));
            c.draw_series(naive.iter().map(|p| {
                Circle::new((p.render_s, y(p.vs_a.rel_rmse_denoised)), 2, BLACK.filled())
            }))?;
            c.draw_series(DashedLineSeries::new(
                naive
                    .iter()
                    .map(|p| (p.render_s, y(p.vs_b.rel_rmse_denoised))),
                3,
                3,
                BLACK.mix(0.5).into(),
            ))?;
            for (mi, m) in labels.iter().enumerate() {
                let col = colours[mi % colours.len()];
                let pts: Vec<&&Point> = here.iter().filter(|p| &p.method == m).collect();
                if pts.is_empty() {
                    continue;
                }
                c.draw_series(LineSeries::new(
                    pts.iter()
                        .map(|p| (p.render_s, y(p.vs_a.rel_rmse_denoised))),
                    col.stroke_width(2),
                ))?
                .label(m.as_str())
                .legend(move |(x, yy)| {
                    PathElement::new(vec![(x, yy), (x + 14, yy)], col.stroke_width(3))
                });
                c.draw_series(pts.iter().map(|p| {
                    Circle::new((p.render_s, y(p.vs_a.rel_rmse_denoised)), 3, col.filled())
                }))?;
                c.draw_series(pts.iter().map(|p| {
                    Circle::new(
                        (p.render_s + p.build_s, y(p.vs_a.rel_rmse_denoised)),
                        3,
                        col.stroke_width(1),
                    )
                }))?;
            }
            if pi == 0 && side.is_none() {
                c.configure_series_labels()
                    .label_font(("sans-serif", 10))
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()?;
            }
        }
        if let Some(side) = &side {
            let entries = std::iter::once(("naive".to_string(), BLACK)).chain(
                labels
                    .iter()
                    .enumerate()
                    .map(|(i, m)| (m.clone(), colours[i % colours.len()])),
            );
            for (i, (label, col)) in entries.enumerate() {
                let y = 40 + 16 * i as i32;
                side.draw(&PathElement::new(
                    vec![(6, y), (22, y)],
                    col.stroke_width(3),
                ))?;
                side.draw(&Text::new(
                    label,
                    (28, y - 6),
                    ("sans-serif", 11).into_font(),
                ))?;
            }
        }
        root.present()?;
    }
    save_rgb(path, w, h, buf)
}
