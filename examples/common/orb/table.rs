//! The orb's table: times and errors of every row (reference (a), reference (b) measured against
//! (a), each glint model), printed and as CSV.

use super::{MethodRow, OrbOptions, ReferenceRow};
use std::fmt::Write as _;

/// Prints the run's settings line, the column header, the reference's row and one row per method.
pub fn print(
    opts: &OrbOptions,
    name: &str,
    (map_width, map_height): (usize, usize),
    map_s: f64,
    reference: &ReferenceRow,
    rows: &[MethodRow],
) {
    println!(
        "orb: {name} map {}x{} ({map_s:.1} s), tiles {}x{}, image {}², σ_ε {}, Gaussian pixel \
         kernel k_P for every row",
        map_width, map_height, opts.tiles.x, opts.tiles.y, opts.size, opts.sigma_eps
    );
    println!(
        "{:<44} {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "method (errors vs (a))",
        "build s",
        "render s",
        "rel RMSE",
        "denoised",
        "4x4",
        "energy",
        "vs (b)"
    );
    let (ref_label, ref_s, noise) = (&reference.label, reference.render_s, reference.noise);
    println!(
        "{ref_label:<44} {:>8} {ref_s:>8.2} {noise:>9.3} {:>9} {:>9} {:>9} {:>9}",
        "-", "(noise)", "-", "-", "-"
    );
    for row in rows {
        let (m, e, vs_b) = (row.rendered, &row.errors, row.vs_b);
        println!(
            "{:<44} {:>8.2} {:>8.2} {:>9.3} {:>9.3} {:>9.3} {:>+9.3} {:>9.3}",
            m.label,
            m.build_s,
            m.render_s,
            e.rel_rmse,
            e.rel_rmse_denoised,
            e.rel_rmse_blocks,
            e.energy,
            vs_b
        );
    }
}

/// The CSV of the table: the reference's line, then one per method (the (b) row's "vs (b)" column
/// is its own noise).
pub fn csv(name: &str, reference: &ReferenceRow, rows: &[MethodRow]) -> String {
    let mut csv = String::from(
        "map,method,build_s,render_s,rel_rmse,rel_rmse_denoised,rel_rmse_4x4,energy_error,\
         rel_rmse_denoised_vs_b,reference_noise\n",
    );
    let (ref_label, ref_s, noise) = (&reference.label, reference.render_s, reference.noise);
    let _ = writeln!(csv, "{name},\"{ref_label}\",0,{ref_s:.3},,,,,,{noise:.4}");
    for row in rows {
        let (m, e, vs_b) = (row.rendered, &row.errors, row.vs_b);
        let _ = writeln!(
            csv,
            "{name},\"{}\",{:.3},{:.3},{:.4},{:.4},{:.4},{:.4},{},",
            m.label,
            m.build_s,
            m.render_s,
            e.rel_rmse,
            e.rel_rmse_denoised,
            e.rel_rmse_blocks,
            e.energy,
            if vs_b.is_nan() {
                format!("noise {:.4}", reference.noise_b)
            } else {
                format!("{vs_b:.4}")
            }
        );
    }
    csv
}
