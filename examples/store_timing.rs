//! Build against load: how long each glint model takes to build from a normal map, and to load back
//! from its saved file (docs/format.md), with the memory it holds per texel and its file size.
//!
//! `cargo run --release --example store_timing -- [--size N] [--loads K] [--models LIST]` (default
//! 2048² bumpy map, 5 loads per build, every model; LIST is a comma-separated subset of `normal`,
//! `mixture` (full and compact storage), `compact` (compact only), `pn`, `binmap`). Builds and loads alternate (build, loads, build, loads) so that a change of
//! machine load hits both; files are saved to and loaded from memory (a `Vec<u8>`), so disk speed is
//! left out. Prints a Markdown table (docs/results.md, "Saving and loading built maps").
//!
//! With each load it times two floors in the same process: filling fresh memory of the loaded model's
//! size (allocate and write every byte once: the page faults and stores any load must pay, since the
//! model's memory is new) and copying the file into fresh memory. Their ratio to the build is the
//! most that any loader of this in-memory layout could reach on the machine.
//!
//! Also charts the medians (`--out DIR`, default target/brdf-out): `store_build_load.png`, per model
//! the build, the load and the fill floor on a log time axis, with the target (load at
//! build / 20) marked.

use brdf_examples::common;

use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{LobeStorage, MixtureParams};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, NormalMap};
use brdf::glint::{PositionNormalMap, bumpy};
use std::time::Instant;

fn arg(name: &str) -> Option<usize> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
}

/// Whether model `key` was asked for (`--models a,b`; all when absent).
fn wanted(key: &str) -> bool {
    let args: Vec<String> = std::env::args().collect();
    match args.iter().position(|a| a == "--models") {
        Some(i) => args
            .get(i + 1)
            .is_some_and(|list| list.split(',').any(|m| m == key)),
        None => true,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

struct Row {
    name: &'static str,
    builds: Vec<f64>,
    loads: Vec<f64>,
    /// Filling fresh memory of the loaded model's size.
    fills: Vec<f64>,
    /// Copying the file into fresh memory.
    copies: Vec<f64>,
    file_bytes: usize,
    memory_bytes: usize,
}

/// Seconds taken by `f`, its result kept alive until timed.
fn timed<T>(f: impl FnOnce() -> T) -> f64 {
    let t = Instant::now();
    let v = f();
    let s = t.elapsed().as_secs_f64();
    std::hint::black_box(&v);
    s
}

/// Times `rounds` × (one build, `loads` loads of its saved file).
fn measure<M>(
    name: &'static str,
    rounds: usize,
    loads: usize,
    build: impl Fn() -> M,
    save: impl Fn(&M, &mut Vec<u8>),
    load: impl Fn(&[u8]) -> M,
    memory: impl Fn(&M) -> usize,
) -> Row {
    let mut row = Row {
        name,
        builds: Vec::new(),
        loads: Vec::new(),
        fills: Vec::new(),
        copies: Vec::new(),
        file_bytes: 0,
        memory_bytes: 0,
    };
    for _ in 0..rounds {
        let t = Instant::now();
        let model = build();
        row.builds.push(t.elapsed().as_secs_f64());
        let mut file = Vec::new();
        save(&model, &mut file);
        row.file_bytes = file.len();
        row.memory_bytes = memory(&model);
        drop(model);
        for _ in 0..loads {
            let t = Instant::now();
            let m = load(&file);
            row.loads.push(t.elapsed().as_secs_f64());
            std::hint::black_box(&m);
            drop(m);
            row.fills
                .push(timed(|| vec![1u8; std::hint::black_box(row.memory_bytes)]));
            row.copies.push(timed(|| file.to_vec()));
        }
        eprintln!(
            "{name}: build {:.3} s, last load {:.4} s",
            row.builds.last().unwrap(),
            row.loads.last().unwrap()
        );
    }
    row
}

/// The chart of build, load and fill-floor medians per model (log time axis, milliseconds).
fn chart(path: &std::path::Path, rows: &[Row], n: usize) -> common::Res<()> {
    use plotters::prelude::*;
    common::register_font();
    let ms = |v: &[f64]| 1e3 * median(v.to_vec());
    let all: Vec<f64> = rows
        .iter()
        .flat_map(|r| {
            [
                ms(&r.builds),
                ms(&r.loads),
                ms(&r.fills),
                ms(&r.builds) / 20.0,
            ]
        })
        .collect();
    let lo = all.iter().copied().fold(f64::INFINITY, f64::min) / 2.0;
    let hi = all.iter().copied().fold(0.0, f64::max) * 2.0;
    // One row band per model and one more at the bottom for the legend.
    let (w, h) = (900u32, 120 + 90 * (rows.len() as u32 + 1));
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let k = rows.len() as f64;
        let mut c = ChartBuilder::on(&root)
            .caption(
                format!("Build against load, bumpy {n}² map (medians; log time)"),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(210)
            .build_cartesian_2d((lo..hi).log_scale(), -1.6..k - 0.4)?;
        let names: Vec<&str> = rows.iter().map(|r| r.name).collect();
        c.configure_mesh()
            .x_desc("milliseconds")
            .y_labels(5 * (rows.len() + 2))
            .y_label_formatter(&|y| {
                let i = y.round();
                if (y - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                    names[names.len() - 1 - i as usize].to_string()
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .draw()?;
        let series = [
            ("build", RGBColor(49, 104, 142)),
            ("load", RGBColor(230, 120, 20)),
            (
                "fill floor (allocate and write the model's memory once)",
                RGBColor(150, 150, 150),
            ),
        ];
        for (s, &(label, colour)) in series.iter().enumerate() {
            let bars: Vec<_> = rows
                .iter()
                .enumerate()
                .map(|(i, r)| {
                    let v = ms(match s {
                        0 => &r.builds,
                        1 => &r.loads,
                        _ => &r.fills,
                    });
                    let y = (rows.len() - 1 - i) as f64 + 0.25 - 0.25 * s as f64;
                    Rectangle::new([(lo, y - 0.1), (v, y + 0.1)], colour.filled())
                })
                .collect();
            c.draw_series(bars)?.label(label).legend(move |(x, y)| {
                Rectangle::new([(x, y - 5), (x + 12, y + 5)], colour.filled())
            });
        }
        let target = rows.iter().enumerate().map(|(i, r)| {
            let y = (rows.len() - 1 - i) as f64;
            let x = ms(&r.builds) / 20.0;
            PathElement::new(vec![(x, y - 0.42), (x, y + 0.42)], RED.stroke_width(2))
        });
        c.draw_series(target)?
            .label("target: load at build / 20")
            .legend(|(x, y)| {
                PathElement::new(vec![(x + 6, y - 6), (x + 6, y + 6)], RED.stroke_width(2))
            });
        c.configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()?;
        root.present()?;
    }
    common::save_rgb(path, w, h, buf)
}

fn main() {
    let n = arg("--size").unwrap_or(2048);
    let loads = arg("--loads").unwrap_or(5);
    let map = bumpy(n, n, 0.25, 4.0, 1).unwrap();
    let texels = (n * n) as f64;
    let rows = vec![
        wanted("normal").then(|| {
            measure(
                "NormalMap (from slopes)",
                2,
                loads,
                || NormalMap::from_slopes(n, n, map.slopes().to_vec()).unwrap(),
                |m, f| m.save(f).unwrap(),
                |f| NormalMap::load(&mut &f[..]).unwrap(),
                |m| m.slopes().len() * 8,
            )
        }),
        wanted("mixture").then(|| {
            measure(
                "BeckmannMixture",
                2,
                loads,
                || BeckmannMixture::build(&map, MixtureParams::default()).unwrap(),
                |m, f| m.save(f).unwrap(),
                |f| BeckmannMixture::load(&mut &f[..]).unwrap(),
                |m| m.memory().total(),
            )
        }),
        // Compact storage (issue 16 item 5), with the `mixture` models or as `compact`.
        (wanted("mixture") || wanted("compact")).then(|| {
            let p = MixtureParams {
                storage: LobeStorage::Compact,
                ..MixtureParams::default()
            };
            measure(
                "BeckmannMixture, compact",
                2,
                loads,
                || BeckmannMixture::build(&map, p).unwrap(),
                |m, f| m.save(f).unwrap(),
                |f| BeckmannMixture::load(&mut &f[..]).unwrap(),
                |m| m.memory().total(),
            )
        }),
        wanted("pn").then(|| {
            measure(
                "PositionNormalMap",
                2,
                loads,
                || PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap(),
                |m, f| m.save(f).unwrap(),
                |f| PositionNormalMap::load(&mut &f[..]).unwrap(),
                |m| {
                    let b = m.memory();
                    b.element_bytes + b.hierarchy_bytes + b.filtered_bytes
                },
            )
        }),
        wanted("binmap").then(|| {
            measure(
                "BinMap",
                2,
                loads,
                || BinMap::build(&map, BinMapParams::default()).unwrap(),
                |m, f| m.save(f).unwrap(),
                |f| BinMap::load(&mut &f[..]).unwrap(),
                |m| m.memory().total(),
            )
        }),
    ];
    let rows: Vec<Row> = rows.into_iter().flatten().collect();
    println!(
        "map: bumpy {n}², {} builds and {} loads per model",
        2,
        2 * loads
    );
    println!();
    println!(
        "| model | build (median) | load (median) | build / load | fill model memory | copy file | \
         build / fill | file B/texel | memory B/texel |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        let (b, l) = (median(r.builds.clone()), median(r.loads.clone()));
        let (fill, copy) = (median(r.fills.clone()), median(r.copies.clone()));
        println!(
            "| {} | {:.3} s | {:.1} ms | {:.1}× | {:.1} ms | {:.1} ms | {:.0}× | {:.2} | {:.2} |",
            r.name,
            b,
            1e3 * l,
            b / l,
            1e3 * fill,
            1e3 * copy,
            b / fill,
            r.file_bytes as f64 / texels,
            r.memory_bytes as f64 / texels
        );
    }
    let path = common::out_dir()
        .map(|d| d.join("store_build_load.png"))
        .expect("output directory");
    match chart(&path, &rows, n) {
        Ok(()) => println!("\nchart: {}", path.display()),
        Err(e) => eprintln!("chart not written: {e}"),
    }
}
