//! Caller-provided scratch memory for glint patches, so that a renderer's shading loop allocates
//! nothing per shading point.
//!
//! A patch built with `patch_in(footprint, &scratch)` takes spare buffers from the scratch for its
//! lifetime and gives them back, with their capacity, when it drops. The scratch is shared, not
//! borrowed mutably: several patches built from one scratch can be alive at once (one BSDF per path
//! vertex, a layered material's layers), each holding its own buffers. After a warm-up (the largest
//! footprint and the most live patches seen so far), `patch_in` + `d` / `lambda` /
//! `projected_area` / the samplers and their densities perform no heap allocation. One
//! [`GlintScratch`] per thread serves every glint model; it is `Send + Sync`, so a renderer keeps
//! one in each worker's thread-local state or arena.

use std::any::Any;
use std::marker::PhantomData;
use std::sync::Mutex;

/// Reusable buffers for the patches of every glint model (see the module docs).
///
/// Holds no data between patches, only capacity: its memory is the working set of the live patches
/// at the busiest moment (about 16 bytes per lobe slot of a mixture footprint, 24 + 32 per element
/// of a position-normal footprint). `Default` is empty and allocates nothing.
///
/// Each model keeps its buffer types in pools found by type (a short scan under an uncontended
/// lock), so a model registers nothing here. Taking and giving back buffers costs two lock
/// round trips per buffer type per patch.
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
/// let scratch = GlintScratch::default(); // one per render thread
/// for px in 0..4 {
///     let fp = Footprint::isotropic_texels(Vec2::new(0.1 * px as f32, 0.5), 16.0, 32, 32);
///     let patch = model.patch_in(&fp, &scratch); // reuses the scratch's buffers
///     // A second live patch from the same scratch (a path's next vertex, say).
///     let next = model.patch_in(&fp, &scratch);
///     assert!(patch.d(Vec3::Z) >= 0.0 && next.d(Vec3::Z) == patch.d(Vec3::Z));
/// } // each patch gives its buffers back when it drops
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Debug, Default)]
pub struct GlintScratch {
    /// One pool per buffer type: a `Pool<T>` boxed as `Any`.
    pools: Mutex<Vec<Box<dyn Any + Send>>>,
}

/// The spare buffers of one type: a stack, so that N live patches hold N buffers and give them
/// back when they drop.
struct Pool<T>(Vec<Box<T>>);

impl GlintScratch {
    /// Where the buffers of type `T` are taken from and given back to.
    pub(crate) fn home<T: Default + Send + 'static>(&self) -> Home<'_, T> {
        Home {
            scratch: self,
            _buffers: PhantomData,
        }
    }

    /// Runs `f` on the pool of `T` (created empty on first request), under the lock.
    fn with_pool<T: Send + 'static, R>(&self, f: impl FnOnce(&mut Vec<Box<T>>) -> R) -> R {
        let mut pools = self.pools.lock().unwrap_or_else(|p| p.into_inner());
        let i = match pools.iter().position(|p| p.is::<Pool<T>>()) {
            Some(i) => i,
            None => {
                pools.push(Box::new(Pool::<T>(Vec::new())));
                pools.len() - 1
            }
        };
        match pools[i].downcast_mut::<Pool<T>>() {
            Some(pool) => f(&mut pool.0),
            // Pool i holds a `Pool<T>`: it was found or pushed as one just above.
            None => unreachable!("scratch pool of the wrong type"),
        }
    }
}

/// The pool of one buffer type in a caller's [`GlintScratch`]: `take` hands out a spare buffer (or
/// an empty one), `give` puts one back with its capacity.
pub(crate) struct Home<'a, T> {
    scratch: &'a GlintScratch,
    _buffers: PhantomData<fn() -> T>,
}

impl<T> Clone for Home<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Home<'_, T> {}

impl<T: Default + Send + 'static> Home<'_, T> {
    /// A spare buffer of the pool (stale content, kept capacity), or an empty one.
    pub(crate) fn take(self) -> Box<T> {
        self.scratch
            .with_pool(|pool: &mut Vec<Box<T>>| pool.pop())
            .unwrap_or_default()
    }

    /// Puts `buffer` back into the pool.
    pub(crate) fn give(self, buffer: Box<T>) {
        self.scratch.with_pool(|pool| pool.push(buffer));
    }
}

/// Buffers `T` lent to one patch and filled at construction: taken from the caller's scratch (or
/// fresh), given back when the patch drops. Cloning detaches the clone from the scratch. The
/// buffers are boxed, so that a patch holding them stays small (a patch is moved a few times
/// between its model and the renderer's BSDF: a box moves as one pointer).
pub(crate) struct Lent<'a, T: Default + Send + 'static> {
    home: Option<Home<'a, T>>,
    /// `Some` for the whole life of the value; `None` only inside `drop`.
    val: Option<Box<T>>,
}

impl<'a, T: Default + Send + 'static> Lent<'a, T> {
    /// Takes buffers from `home` (if any) for the patch's lifetime; their content is stale.
    pub(crate) fn new(home: Option<Home<'a, T>>) -> Self {
        let val = home.map(Home::take).unwrap_or_default();
        Lent {
            home,
            val: Some(val),
        }
    }
}

impl<T: Default + Send + 'static> std::ops::Deref for Lent<'_, T> {
    type Target = T;
    #[inline]
    fn deref(&self) -> &T {
        match &self.val {
            Some(v) => v,
            None => unreachable!("a lent buffer is read after its drop"),
        }
    }
}

impl<T: Default + Send + 'static> std::ops::DerefMut for Lent<'_, T> {
    #[inline]
    fn deref_mut(&mut self) -> &mut T {
        match &mut self.val {
            Some(v) => v,
            None => unreachable!("a lent buffer is written after its drop"),
        }
    }
}

impl<T: Default + Send + 'static> Drop for Lent<'_, T> {
    fn drop(&mut self) {
        if let (Some(home), Some(val)) = (self.home.take(), self.val.take()) {
            home.give(val);
        }
    }
}

impl<T: Default + Send + 'static + Clone> Clone for Lent<'_, T> {
    fn clone(&self) -> Self {
        Lent {
            home: None,
            val: Some(Box::new(T::clone(self))),
        }
    }
}

impl<T: Default + Send + 'static + std::fmt::Debug> std::fmt::Debug for Lent<'_, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        T::fmt(self, f)
    }
}
