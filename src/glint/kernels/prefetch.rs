//! Prefetch hints: asking the CPU to bring memory a query will read into its caches ahead of the
//! read, so that the loads of a footprint's data overlap instead of each stalling in turn. A hint
//! changes no value; on targets other than x86-64 it does nothing.

/// Asks for every cache line that holds part of `data`.
#[inline(always)]
pub(crate) fn prefetch<T: ?Sized>(data: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        const LINE: usize = 64;
        let bytes = std::mem::size_of_val(data);
        if bytes == 0 {
            return;
        }
        let p = (data as *const T).cast::<i8>();
        // From the line holding the first byte to the line holding the last.
        let lines = ((p as usize % LINE) + bytes).div_ceil(LINE);
        let first = p.wrapping_sub(p as usize % LINE);
        for k in 0..lines {
            // SAFETY: a prefetch is a hint: it never faults and reads nothing into the program,
            // whatever the address; the address is formed with wrapping arithmetic (no pointer
            // offset is assumed in bounds); SSE, which it needs, is part of the x86-64 baseline.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(first.wrapping_add(k * LINE)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = data;
}
