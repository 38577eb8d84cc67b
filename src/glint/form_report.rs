//! The report of the forms a glint model's patches take across footprint sizes under a renderer's
//! options ([`FormReport`], [`GlintModel::forms`]): what a renderer logs once per material so that
//! a form whose work grows with the footprint (a gather) is visible before it costs a frame.

use super::{Footprint, GlintModel, GlintNdf, GlintOptions, PatchForm};
use glam::Vec2;
use std::fmt;

/// One row of a [`FormReport`]: the form of the patch of an isotropic footprint of `texels`
/// texels at the map's centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FormRow {
    /// The footprint's area in texels of the model's map.
    pub texels: f32,
    /// The form its patch takes.
    pub form: PatchForm,
}

/// The forms a model's patches take under one set of options, at isotropic footprints from a
/// quarter of a texel to the whole map, in steps of 4× ([`GlintModel::forms`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FormReport {
    /// The model's name ([`GlintModel::name`]).
    pub model: &'static str,
    /// One row per footprint size, smallest first.
    pub rows: Vec<FormRow>,
}

impl FormReport {
    /// The smallest footprint (texels) from which no reported form grows with the footprint, or
    /// `None` when the largest one still does.
    pub fn bounded_from(&self) -> Option<f32> {
        let last_growing = self
            .rows
            .iter()
            .rposition(|r| r.form.grows_with_footprint());
        match last_growing {
            None => self.rows.first().map(|r| r.texels),
            Some(i) => self.rows.get(i + 1).map(|r| r.texels),
        }
    }
}

impl fmt::Display for FormReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: forms by footprint (texels, isotropic, map centre)",
            self.model
        )?;
        for r in &self.rows {
            let grows = if r.form.grows_with_footprint() {
                "  [work grows with the footprint]"
            } else {
                ""
            };
            writeln!(f, "  {:>9}: {}{grows}", format_texels(r.texels), r.form)?;
        }
        match self.bounded_from() {
            Some(t) => write!(f, "  bounded work from {} texels", format_texels(t)),
            None => write!(f, "  work grows with the footprint up to the whole map"),
        }
    }
}

fn format_texels(t: f32) -> String {
    if t < 1.0 {
        format!("{t}")
    } else {
        format!("{}", t.round() as u64)
    }
}

/// The footprint sizes a report probes: 4^k / 4 texels up to the map's area.
fn report_sizes(width: usize, height: usize) -> impl Iterator<Item = f32> {
    let area = (width * height) as f32;
    (0..)
        .map(|k| 0.25 * 4f32.powi(k))
        .take_while(move |&t| t <= area)
}

impl GlintModel {
    /// The forms this model's patches take under `options` (its field of [`GlintOptions`]) at
    /// isotropic footprints of ¼, 1, 4, … texels up to the whole map, centred on the map: what a
    /// renderer logs once per material to see which footprint sizes gather (work growing with the
    /// footprint) and which are served by a bounded form, on this map, with these options. One
    /// patch per row, made as a renderer makes it; the level of detail of gathered footprints can
    /// differ at other centres (it reads the map's local errors), the choice between forms does
    /// not (it reads the footprint's area and errors measured per level).
    pub fn forms(&self, options: &GlintOptions) -> FormReport {
        let (width, height) = self.map_size();
        let center = Vec2::splat(0.5);
        let rows = report_sizes(width, height)
            .map(|texels| {
                let fp = Footprint::isotropic_texels(center, texels, width, height);
                FormRow {
                    texels,
                    form: self.patch_with(&fp, options, None).form(),
                }
            })
            .collect();
        FormReport {
            model: self.name(),
            rows,
        }
    }
}
