//! [`PreparedView`]: a value a patch computes once for the view direction it is prepared for, by
//! an explicit step (the patches' `prepare_view`, called by `Material::bsdf` with the shading point's
//! wo), so that the queries a renderer makes at one shading point and one wo (`eval_pdf` at a few
//! wi, `sample`, the densities) pay the pass over the patch's lobes once instead of once per query.
//!
//! Immutable once made: a query at the prepared wo (the same bits) reads the value, a query at any
//! other wo computes its own, and both are the number the pass gives, bit for bit. Nothing is kept
//! lazily: a patch that was not prepared computes per query.

use glam::Vec3;

/// One f64 computed for one direction, keyed by the direction's bits (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct PreparedView {
    key: Option<[u32; 3]>,
    value: f64,
}

/// The key of a direction: its three components' bits (a deterministic pass gives one value per
/// key; −0.0 and 0.0 are different keys).
fn key_of(w: Vec3) -> [u32; 3] {
    [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()]
}

impl PreparedView {
    /// No prepared view: every query computes its own value.
    pub(crate) const NONE: PreparedView = PreparedView {
        key: None,
        value: 0.0,
    };

    /// `value` prepared for the direction `w`.
    pub(crate) fn new(w: Vec3, value: f64) -> PreparedView {
        PreparedView {
            key: Some(key_of(w)),
            value,
        }
    }

    /// Whether `w` is the prepared direction (the same bits).
    #[inline]
    pub(crate) fn is(&self, w: Vec3) -> bool {
        self.key == Some(key_of(w))
    }

    /// The prepared value if `w` is the prepared direction, else `compute()` (not kept).
    #[inline]
    pub(crate) fn get_or(&self, w: Vec3, compute: impl FnOnce() -> f64) -> f64 {
        match self.key {
            Some(k) if k == key_of(w) => self.value,
            _ => compute(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_only_the_prepared_direction() {
        let a = Vec3::new(0.1, 0.2, 0.9);
        let p = PreparedView::new(a, 1.0);
        assert_eq!(p.get_or(a, || 9.0), 1.0);
        assert_eq!(p.get_or(Vec3::new(0.3, 0.0, 0.8), || 2.0), 2.0);
        // Nothing was kept by the other query.
        assert_eq!(p.get_or(a, || 9.0), 1.0);
        // −0.0 and 0.0 are different keys.
        let z = PreparedView::new(Vec3::new(-0.0, 0.0, 1.0), 4.0);
        assert_eq!(z.get_or(Vec3::Z, || 5.0), 5.0);
        assert_eq!(PreparedView::NONE.get_or(Vec3::Z, || 6.0), 6.0);
        assert_eq!(PreparedView::default(), PreparedView::NONE);
    }
}
