//! The footprint parallelogram in texel units and its exact overlap with axis-aligned rectangles:
//! a separating-axis classification (inside / outside / partial) for kd-tree nodes and texels, the
//! exact area |A ∩ T| of a rectangle (in closed form where one edge line of A crosses it, by polygon
//! clipping where two do), and for a row of unit cells the bounds of the cells that meet A and of
//! those inside it (the moment chain's row-wise read).
//!
//! All in `f64`: texel coordinates of a 2048² map need 11 bits, leaving ~40 bits for the fractional
//! geometry, so rounding in areas is ~1e-12 texel² per texel.
//!
//! # Reference
//! \[Atanasov2020\] §2 (D_A^H sums |A ∩ T_k|); the clipping is \[SutherlandHodgman1974\] re-entrant
//! polygon clipping (1974), specialised to a convex quadrilateral and a rectangle.

/// How an axis-aligned rectangle lies relative to the parallelogram.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Overlap {
    /// No common interior point.
    Outside,
    /// Contained in the parallelogram.
    Inside,
    /// Neither: the boundary crosses it.
    Partial,
}

/// The parallelogram {c + s a + t b : s, t ∈ [−½, ½]} in texel units, with the affine map
/// p ↦ (s, t) precomputed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Parallelogram {
    c: [f64; 2],
    a: [f64; 2],
    b: [f64; 2],
    /// Rows of M⁻¹ with M = [a b]: s = gs·(p − c), t = gt·(p − c).
    gs: [f64; 2],
    gt: [f64; 2],
    /// Half extents of the axis-aligned bounding box: (|a_x| + |b_x|)/2, (|a_y| + |b_y|)/2.
    half_box: [f64; 2],
    area: f64,
}

impl Parallelogram {
    /// From centre and edges; `None` if the edges are not finite or span (numerically) no area.
    pub(crate) fn new(c: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<Parallelogram> {
        let det = a[0] * b[1] - a[1] * b[0];
        let scale = (a[0].abs() + a[1].abs()) * (b[0].abs() + b[1].abs());
        if !(det.is_finite() && c.iter().all(|v| v.is_finite()) && det.abs() > 1e-12 * scale) {
            return None;
        }
        let gs = [b[1] / det, -b[0] / det];
        let gt = [-a[1] / det, a[0] / det];
        Some(Parallelogram {
            c,
            a,
            b,
            gs,
            gt,
            half_box: [
                0.5 * (a[0].abs() + b[0].abs()),
                0.5 * (a[1].abs() + b[1].abs()),
            ],
            area: det.abs(),
        })
    }

    /// Area |det[a b]| in texels².
    #[inline]
    pub(crate) fn area(&self) -> f64 {
        self.area
    }

    /// The centre.
    #[inline]
    pub(crate) fn center(&self) -> [f64; 2] {
        self.c
    }

    /// The axis-aligned bounding box (min, max).
    #[inline]
    pub(crate) fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        (
            [self.c[0] - self.half_box[0], self.c[1] - self.half_box[1]],
            [self.c[0] + self.half_box[0], self.c[1] + self.half_box[1]],
        )
    }

    /// The parallelogram with x scaled by `kx` and y by `ky` (an axis scaling keeps it a
    /// parallelogram); `None` if that leaves it degenerate.
    pub(crate) fn scaled(&self, kx: f64, ky: f64) -> Option<Parallelogram> {
        let f = |p: [f64; 2]| [p[0] * kx, p[1] * ky];
        Parallelogram::new(f(self.c), f(self.a), f(self.b))
    }

    /// The same parallelogram translated by `d`.
    #[inline]
    pub(crate) fn translated(&self, d: [f64; 2]) -> Parallelogram {
        Parallelogram {
            c: [self.c[0] + d[0], self.c[1] + d[1]],
            ..*self
        }
    }

    /// The point c + s a + t b.
    #[inline]
    pub(crate) fn point(&self, s: f64, t: f64) -> [f64; 2] {
        [
            self.c[0] + s * self.a[0] + t * self.b[0],
            self.c[1] + s * self.a[1] + t * self.b[1],
        ]
    }

    /// The separating-axis quantities of the rectangle [x0, x1] × [y0, y1] on P's own axes: the
    /// rectangle's centre in (s, t) and its half ranges (rs, rt) there, or `None` when the axes x
    /// and y (the bounding boxes) separate it from P.
    #[inline]
    fn axes(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> Option<[f64; 4]> {
        let (hx, hy) = (0.5 * (x1 - x0), 0.5 * (y1 - y0));
        let (dx, dy) = (0.5 * (x0 + x1) - self.c[0], 0.5 * (y0 + y1) - self.c[1]);
        if dx.abs() >= hx + self.half_box[0] || dy.abs() >= hy + self.half_box[1] {
            return None;
        }
        let s = self.gs[0] * dx + self.gs[1] * dy;
        let rs = self.gs[0].abs() * hx + self.gs[1].abs() * hy;
        let t = self.gt[0] * dx + self.gt[1] * dy;
        let rt = self.gt[0].abs() * hx + self.gt[1].abs() * hy;
        Some([s, rs, t, rt])
    }

    /// Classifies the rectangle [x0, x1] × [y0, y1] by the separating-axis theorem on the four edge
    /// normals (x, y and the parallelogram's two): exact for convex polygons. Touching along an edge
    /// or a corner counts as `Outside` (no common area).
    #[inline]
    pub(crate) fn classify(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> Overlap {
        let Some([s, rs, t, rt]) = self.axes(x0, y0, x1, y1) else {
            return Overlap::Outside;
        };
        // Axes of the parallelogram: the range of s (t) over the rectangle against [−½, ½].
        if s.abs() >= 0.5 + rs || t.abs() >= 0.5 + rt {
            return Overlap::Outside;
        }
        if s.abs() + rs <= 0.5 && t.abs() + rt <= 0.5 {
            Overlap::Inside
        } else {
            Overlap::Partial
        }
    }

    /// |P ∩ [x0, x1] × [y0, y1]| in texels², exact: 0 and the rectangle's area where
    /// [`Parallelogram::classify`] decides, the closed form of [`half_plane_fraction`] where one
    /// edge line of P alone crosses the rectangle (the other three half-planes of P hold it whole:
    /// the rectangle's cells along a footprint's sides), and [`Parallelogram::clipped_area`] where
    /// two or more do (near P's corners, or across a thin P).
    #[inline]
    pub(crate) fn overlap_area(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
        let Some([s, rs, t, rt]) = self.axes(x0, y0, x1, y1) else {
            return 0.0;
        };
        if s.abs() >= 0.5 + rs || t.abs() >= 0.5 + rt {
            return 0.0;
        }
        let (w, h) = (x1 - x0, y1 - y0);
        // Each half-plane of P, g·(p − c) ≤ ½ for g = ±gs, ±gt, cuts the rectangle when the
        // largest value of g·(p − c) over it, ±s + rs (±t + rt), exceeds ½; it then keeps the
        // part where the value, counted up from its least (±s − rs at one corner), stays below ½.
        let (s_hi, s_lo, t_hi, t_lo) = (s + rs > 0.5, rs - s > 0.5, t + rt > 0.5, rt - t > 0.5);
        let cuts = s_hi as u8 + s_lo as u8 + t_hi as u8 + t_lo as u8;
        if cuts == 0 {
            return w * h;
        }
        if cuts > 1 {
            return self.clipped_area(x0, y0, x1, y1);
        }
        let (g, e) = if s_hi {
            (self.gs, 0.5 - s + rs)
        } else if s_lo {
            (self.gs, 0.5 + s + rs)
        } else if t_hi {
            (self.gt, 0.5 - t + rt)
        } else {
            (self.gt, 0.5 + t + rt)
        };
        w * h * half_plane_fraction(g[0].abs() * w, g[1].abs() * h, e)
    }

    /// |P ∩ [x0, x0 + 1] × [y0, y0 + 1]|: the exact overlap area of the unit texel square whose lower
    /// corner is (x0, y0), in texels² ∈ [0, 1].
    #[cfg(test)]
    pub(crate) fn texel_overlap(&self, x0: f64, y0: f64) -> f64 {
        self.overlap_area(x0, y0, x0 + 1.0, y0 + 1.0)
    }

    /// For the row of unit cells [i, i + 1] × [y0, y1], bounds on i from P's four half-planes
    /// g·(p − c) ≤ ½ (g = ±gs, ±gt), each linear in x once y ranges over [y0, y1]:
    /// `(meet, inside)` with `meet = [lo, hi]` such that the separating-axis test on P's axes
    /// keeps a cell iff lo − 1 < i < hi (every point's value below ½ for some x of the cell, per
    /// half-plane), and `inside = [lo, hi]` such that a cell lies in P iff lo ≤ i and i + 1 ≤ hi
    /// (every point's value at most ½). Bounds may be infinite; a half-plane that misses the whole
    /// row (P's edge parallel to x) empties them as [∞, −∞].
    pub(crate) fn row_bounds(&self, y0: f64, y1: f64) -> ([f64; 2], [f64; 2]) {
        let (mut meet, mut inside) = (
            [f64::NEG_INFINITY, f64::INFINITY],
            [f64::NEG_INFINITY, f64::INFINITY],
        );
        let (dy0, dy1) = (y0 - self.c[1], y1 - self.c[1]);
        for g in [self.gs, self.gt] {
            for sign in [1.0, -1.0] {
                let (gx, gy) = (sign * g[0], sign * g[1]);
                let (a, b) = (gy * dy0, gy * dy1);
                let (least, most) = (a.min(b), a.max(b));
                // g_x (x − c_x) + (the y part) ≤ ½ holds for x on one side of x*.
                let (meet_x, inside_x) = ((0.5 - least) / gx, (0.5 - most) / gx);
                if gx > 0.0 {
                    meet[1] = meet[1].min(self.c[0] + meet_x);
                    inside[1] = inside[1].min(self.c[0] + inside_x);
                } else if gx < 0.0 {
                    meet[0] = meet[0].max(self.c[0] + meet_x);
                    inside[0] = inside[0].max(self.c[0] + inside_x);
                } else {
                    if least >= 0.5 {
                        meet = [f64::INFINITY, f64::NEG_INFINITY];
                    }
                    if most > 0.5 {
                        inside = [f64::INFINITY, f64::NEG_INFINITY];
                    }
                }
            }
        }
        (meet, inside)
    }

    /// Area of P ∩ [x0, x1] × [y0, y1] by clipping P's quadrilateral against the rectangle's four
    /// half-planes (Sutherland–Hodgman: a convex polygon stays convex, ≤ 8 vertices) and the shoelace
    /// formula. Coordinates are taken relative to the rectangle's corner to keep them small. A
    /// half-plane that keeps every vertex is skipped (the clip would return the same polygon), and
    /// the two polygons alternate roles without copies: on a footprint's boundary texels most of the
    /// four clips cut nothing.
    pub(crate) fn clipped_area(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> f64 {
        let (mut p0, mut p1) = (Poly::default(), Poly::default());
        for (s, t) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            let p = self.point(s, t);
            p0.push([p[0] - x0, p[1] - y0]);
        }
        let (mut src, mut dst) = (&mut p0, &mut p1);
        let (w, h) = (x1 - x0, y1 - y0);
        // Each half-plane as (axis, bound, keep-below): x ≥ 0, x ≤ w, y ≥ 0, y ≤ h.
        for (axis, bound, below) in [(0, 0.0, false), (0, w, true), (1, 0.0, false), (1, h, true)] {
            if src.clip_into(axis, bound, below, dst) {
                std::mem::swap(&mut src, &mut dst);
                if src.len < 3 {
                    return 0.0;
                }
            }
        }
        src.area().clamp(0.0, w * h)
    }
}

/// P's separating-axis tests against rectangles with integer corners, in the form a kd-tree walk
/// uses them. P's bounding box (the axes x and y) is tested first, on the integer corners against
/// the box's bounds rounded outward (x₁ ≤ x_lo exactly when x₁ ≤ ⌊x_lo⌋, for an integer x₁): no
/// conversion, and it settles the nodes far from P. P's own axes then take the values of s and t
/// (P = {|s|, |t| ≤ ½}) at the rectangle's centre as affine functions of its corners and their half
/// ranges over it as linear functions of its sides: a few multiplications and no division per node,
/// fewer per unit texel. The decisions are those of [`Parallelogram::classify`] up to rounding of
/// the coordinates (a rectangle touching P's boundary within ~1e-12 texels may be classified
/// otherwise; the exact area of a partly covered texel settles it).
#[derive(Clone, Copy, Debug)]
pub(crate) struct AxisTests {
    /// gs/2 and s_c = −gs·c: s at a rectangle's centre is hgs·(x₀ + x₁, y₀ + y₁) + s_c (likewise
    /// t), from the sums of its corners' coordinates.
    hgs: [f64; 2],
    hgt: [f64; 2],
    s_c: f64,
    t_c: f64,
    /// |gs|/2, |gt|/2: the half range of s over a w × h rectangle is |gs₀|/2 w + |gs₁|/2 h.
    ags: [f64; 2],
    agt: [f64; 2],
    /// gs, gt and the values of s and t at the centre of the unit texel [0, 1]²: at texel (i, j)
    /// they are gs·(i, j) + s_texel and gt·(i, j) + t_texel.
    gs: [f64; 2],
    gt: [f64; 2],
    s_texel: f64,
    t_texel: f64,
    /// For unit texels: |s| ≥ `s_out` (or |t| ≥ `t_out`) separates the texel from P, and
    /// |s| ≤ `s_in` and |t| ≤ `t_in` put it inside (½ ± the half range of s, t over a texel).
    s_out: f64,
    s_in: f64,
    t_out: f64,
    t_in: f64,
    /// P's bounding box rounded outward to integers (saturated to `u32`): a rectangle with
    /// x₁ ≤ lo[0] or x₀ ≥ hi[0] (likewise y) has no common area with P.
    lo: [u32; 2],
    hi: [u32; 2],
}

impl AxisTests {
    /// The tests of `p`.
    pub(crate) fn new(p: &Parallelogram) -> AxisTests {
        let (gs, gt, c) = (p.gs, p.gt, p.c);
        let s_c = -(gs[0] * c[0] + gs[1] * c[1]);
        let t_c = -(gt[0] * c[0] + gt[1] * c[1]);
        let rs = 0.5 * (gs[0].abs() + gs[1].abs());
        let rt = 0.5 * (gt[0].abs() + gt[1].abs());
        let (lo, hi) = p.bounds();
        // `as u32` saturates: a bound below 0 (above u32::MAX) separates no rectangle of the map on
        // that side (every rectangle on it).
        AxisTests {
            hgs: [0.5 * gs[0], 0.5 * gs[1]],
            hgt: [0.5 * gt[0], 0.5 * gt[1]],
            s_c,
            t_c,
            ags: [0.5 * gs[0].abs(), 0.5 * gs[1].abs()],
            agt: [0.5 * gt[0].abs(), 0.5 * gt[1].abs()],
            gs,
            gt,
            s_texel: s_c + 0.5 * (gs[0] + gs[1]),
            t_texel: t_c + 0.5 * (gt[0] + gt[1]),
            s_out: 0.5 + rs,
            s_in: 0.5 - rs,
            t_out: 0.5 + rt,
            t_in: 0.5 - rt,
            lo: [lo[0].floor() as u32, lo[1].floor() as u32],
            hi: [hi[0].ceil() as u32, hi[1].ceil() as u32],
        }
    }

    /// Classifies the rectangle [x0, x1] × [y0, y1] (integer corners, x0 < x1, y0 < y1) as
    /// [`Parallelogram::classify`] does.
    #[inline]
    pub(crate) fn rect(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> Overlap {
        if x1 <= self.lo[0] || x0 >= self.hi[0] || y1 <= self.lo[1] || y0 >= self.hi[1] {
            return Overlap::Outside;
        }
        let (x0, y0, x1, y1) = (x0 as f64, y0 as f64, x1 as f64, y1 as f64);
        let (sx, sy, w, h) = (x0 + x1, y0 + y1, x1 - x0, y1 - y0);
        let s = (self.hgs[0] * sx + self.hgs[1] * sy + self.s_c).abs();
        let t = (self.hgt[0] * sx + self.hgt[1] * sy + self.t_c).abs();
        let rs = self.ags[0] * w + self.ags[1] * h;
        let rt = self.agt[0] * w + self.agt[1] * h;
        if s >= 0.5 + rs || t >= 0.5 + rt {
            Overlap::Outside
        } else if s + rs <= 0.5 && t + rt <= 0.5 {
            Overlap::Inside
        } else {
            Overlap::Partial
        }
    }

    /// Classifies the unit texel [i, i + 1] × [j, j + 1] as [`Parallelogram::classify`] does.
    #[inline]
    pub(crate) fn texel(&self, i: u32, j: u32) -> Overlap {
        if i < self.lo[0] || i >= self.hi[0] || j < self.lo[1] || j >= self.hi[1] {
            return Overlap::Outside;
        }
        let (x, y) = (i as f64, j as f64);
        let s = (self.gs[0] * x + self.gs[1] * y + self.s_texel).abs();
        let t = (self.gt[0] * x + self.gt[1] * y + self.t_texel).abs();
        if s >= self.s_out || t >= self.t_out {
            Overlap::Outside
        } else if s <= self.s_in && t <= self.t_in {
            Overlap::Inside
        } else {
            Overlap::Partial
        }
    }
}

/// The fraction of the unit square [0, 1]² where u ξ + v η ≤ e (u, v ≥ 0, u + v > 0): a rectangle's
/// part on one side of a line, the rectangle mapped onto the unit square with its axes turned so
/// that the line's value grows along both (u, v its growth across the whole side, e its margin at
/// the least corner).
///
/// With u ≥ v (else the roles swap), the row at height η keeps ξ ≤ f(η) = (e − v η)/u clamped to
/// [0, 1], and f is linear from f₀ = e/u to f₁ = (e − v)/u, so the fraction is
/// (1/(f₀ − f₁)) ∫_{f₁}^{f₀} clamp(f, 0, 1) df: the part of [f₁, f₀] in [0, 1] contributes
/// (b² − a²)/2, the part above 1 its length. Each term is a product or a difference of numbers of
/// one sign, so the result is accurate to a few ulps also for nearly axis-aligned lines (f₀ − f₁
/// small), where the fraction tends to clamp(f₀, 0, 1), its value at f₀ = f₁.
#[inline]
fn half_plane_fraction(u: f64, v: f64, e: f64) -> f64 {
    let (u, v) = if u >= v { (u, v) } else { (v, u) };
    let (hi, lo) = (e / u, (e - v) / u);
    let span = hi - lo;
    if span <= 0.0 {
        return hi.clamp(0.0, 1.0);
    }
    let (a, b) = (lo.max(0.0), hi.min(1.0));
    let middle = if b > a { 0.5 * (b - a) * (a + b) } else { 0.0 };
    let above = (hi - lo.max(1.0)).max(0.0);
    ((middle + above) / span).clamp(0.0, 1.0)
}

/// A convex polygon of at most 8 vertices (a quadrilateral clipped by four half-planes gains at most
/// one vertex per half-plane).
#[derive(Clone, Copy, Default)]
struct Poly {
    v: [[f64; 2]; 8],
    len: usize,
}

impl Poly {
    #[inline]
    fn push(&mut self, p: [f64; 2]) {
        if self.len < self.v.len() {
            self.v[self.len] = p;
            self.len += 1;
        }
    }

    /// Writes into `out` the part with coordinate `axis` ≤ bound (`below`) or ≥ bound, and returns
    /// true; returns false, leaving `out` as it was, when every vertex is already on the kept side
    /// (the part is the polygon itself). Needs at least one vertex.
    #[inline]
    fn clip_into(&self, axis: usize, bound: f64, below: bool, out: &mut Poly) -> bool {
        let inside = |p: &[f64; 2]| {
            if below {
                p[axis] <= bound
            } else {
                p[axis] >= bound
            }
        };
        let vertices = &self.v[..self.len];
        if vertices.iter().all(inside) {
            return false;
        }
        out.len = 0;
        let Some(&last) = vertices.last() else {
            return true;
        };
        let (mut prev, mut prev_in) = (last, inside(&last));
        for &cur in vertices {
            let cur_in = inside(&cur);
            if cur_in != prev_in {
                // The edge crosses the line: its intersection point.
                let f = (bound - prev[axis]) / (cur[axis] - prev[axis]);
                let mut x = [
                    prev[0] + f * (cur[0] - prev[0]),
                    prev[1] + f * (cur[1] - prev[1]),
                ];
                x[axis] = bound;
                out.push(x);
            }
            if cur_in {
                out.push(cur);
            }
            (prev, prev_in) = (cur, cur_in);
        }
        true
    }

    /// Shoelace area (absolute value), summed edge (0, 1), (1, 2), …, (n − 1, 0).
    fn area(&self) -> f64 {
        let vertices = &self.v[..self.len];
        let mut twice = 0.0;
        for pair in vertices.windows(2) {
            let (p, q) = (pair[0], pair[1]);
            twice += p[0] * q[1] - p[1] * q[0];
        }
        if let (Some(&p), Some(&q)) = (vertices.last(), vertices.first()) {
            twice += p[0] * q[1] - p[1] * q[0];
        }
        0.5 * twice.abs()
    }
}

#[cfg(test)]
mod tests;
