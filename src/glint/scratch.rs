//! Caller-provided scratch memory for glint patches, so that a renderer's shading loop allocates
//! nothing per shading point.
//!
//! A patch built with `patch_in(footprint, &mut scratch)` borrows the scratch's buffers for its
//! lifetime and gives them back, with their capacity, when it drops; after a warm-up (the largest
//! footprint seen so far), `patch_in` + `d` / `lambda` / `projected_area` / the samplers and their
//! densities perform no heap allocation. One [`GlintScratch`] per thread serves every glint model (it
//! is `Send`, so a renderer keeps one in each worker's thread-local state or arena).

use std::any::Any;
use std::sync::{Mutex, OnceLock};

/// Reusable buffers for the patches of every glint model (see the module docs).
///
/// Holds no data between patches, only capacity: its memory is the largest patch's working set
/// (about 16 bytes per lobe slot of the largest mixture footprint, 24 + 32 per element of the
/// largest position-normal footprint). `Default` is empty and allocates nothing.
///
/// Each model keeps its own buffer type in one slot, found by type (a short scan of at most one
/// slot per model), so a model registers nothing here.
///
/// # Example
/// ```
/// use brdf::glint::mixture::MixtureParams;
/// use brdf::glint::{BeckmannMixture, Footprint, GlintNdf, GlintScratch};
/// use brdf::ndf::Ndf;
/// use brdf::{Vec2, Vec3};
///
/// let map = brdf::glint::bumpy(32, 32, 0.2, 3.0, 1)?;
/// let model = BeckmannMixture::build(&map, MixtureParams { samples: 16, ..Default::default() })?;
/// let mut scratch = GlintScratch::default(); // one per render thread
/// for px in 0..4 {
///     let fp = Footprint::isotropic_texels(Vec2::new(0.1 * px as f32, 0.5), 16.0, 32, 32);
///     let patch = model.patch_in(&fp, &mut scratch); // reuses the scratch's buffers
///     assert!(patch.d(Vec3::Z) >= 0.0);
/// } // each patch gives its buffers back when it drops
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Debug, Default)]
pub struct GlintScratch {
    slots: Vec<Box<dyn Any + Send>>,
}

impl GlintScratch {
    /// The buffers of type `T` (created empty on first request): each model asks for its own type.
    pub(crate) fn slot<T: Default + Send + 'static>(&mut self) -> &mut T {
        let i = match self.slots.iter().position(|s| s.is::<T>()) {
            Some(i) => i,
            None => {
                self.slots.push(Box::<T>::default());
                self.slots.len() - 1
            }
        };
        match self.slots[i].downcast_mut::<T>() {
            Some(t) => t,
            // Slot i holds a `T`: it was found or pushed as one just above.
            None => unreachable!("scratch slot of the wrong type"),
        }
    }
}

/// Buffers `T` lent to one patch: taken from the caller's scratch (or fresh) at construction,
/// filled on first use through a shared reference, given back to the scratch when the patch drops.
/// Cloning a patch clones the filled buffers and detaches the clone from the scratch.
pub(crate) struct Loan<'a, T: Default> {
    home: Option<&'a mut T>,
    /// The empty buffers (with their capacity) until the first use.
    spare: Mutex<T>,
    filled: OnceLock<T>,
}

impl<'a, T: Default> Loan<'a, T> {
    /// Takes the buffers of `home` (if any) for the patch's lifetime.
    pub(crate) fn new(mut home: Option<&'a mut T>) -> Self {
        let spare = home.as_deref_mut().map(std::mem::take).unwrap_or_default();
        Loan {
            home,
            spare: Mutex::new(spare),
            filled: OnceLock::new(),
        }
    }

    /// The filled buffers; `fill` receives the lent (stale, to be cleared) buffers on the first call.
    #[inline]
    pub(crate) fn get_or_init(&self, fill: impl FnOnce(T) -> T) -> &T {
        self.filled.get_or_init(|| {
            let spare = match self.spare.lock() {
                Ok(mut g) => std::mem::take(&mut *g),
                Err(poisoned) => std::mem::take(&mut *poisoned.into_inner()),
            };
            fill(spare)
        })
    }
}

impl<T: Default> Drop for Loan<'_, T> {
    fn drop(&mut self) {
        if let Some(home) = self.home.take() {
            *home = match self.filled.take() {
                Some(t) => t,
                None => std::mem::take(self.spare.get_mut().unwrap_or_else(|p| p.into_inner())),
            };
        }
    }
}

impl<T: Default + Clone> Clone for Loan<'_, T> {
    fn clone(&self) -> Self {
        let filled = OnceLock::new();
        if let Some(t) = self.filled.get() {
            let _ = filled.set(t.clone());
        }
        Loan {
            home: None,
            spare: Mutex::new(T::default()),
            filled,
        }
    }
}

impl<T: Default + std::fmt::Debug> std::fmt::Debug for Loan<'_, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Loan")
            .field("lent", &self.home.is_some())
            .field("filled", &self.filled.get())
            .finish()
    }
}

/// Buffers `T` lent to one patch and filled at construction: taken from the caller's scratch (or
/// fresh), given back when the patch drops. Cloning detaches the clone from the scratch.
pub(crate) struct Lent<'a, T: Default> {
    home: Option<&'a mut T>,
    val: T,
}

impl<'a, T: Default> Lent<'a, T> {
    /// Takes the buffers of `home` (if any) for the patch's lifetime; their content is stale.
    pub(crate) fn new(mut home: Option<&'a mut T>) -> Self {
        let val = home.as_deref_mut().map(std::mem::take).unwrap_or_default();
        Lent { home, val }
    }
}

impl<T: Default> std::ops::Deref for Lent<'_, T> {
    type Target = T;
    #[inline]
    fn deref(&self) -> &T {
        &self.val
    }
}

impl<T: Default> std::ops::DerefMut for Lent<'_, T> {
    #[inline]
    fn deref_mut(&mut self) -> &mut T {
        &mut self.val
    }
}

impl<T: Default> Drop for Lent<'_, T> {
    fn drop(&mut self) {
        if let Some(home) = self.home.take() {
            *home = std::mem::take(&mut self.val);
        }
    }
}

impl<T: Default + Clone> Clone for Lent<'_, T> {
    fn clone(&self) -> Self {
        Lent {
            home: None,
            val: self.val.clone(),
        }
    }
}

impl<T: Default + std::fmt::Debug> std::fmt::Debug for Lent<'_, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.val.fmt(f)
    }
}
