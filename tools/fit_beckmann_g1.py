#!/usr/bin/env python3
"""Fits the rational function behind the Beckmann masking G1 and visible area in src/ndf/beckmann.rs.

With a = 1/(alpha tan theta) = z/n (z = cos theta, n = alpha(phi) sin theta), Beckmann's Smith
Lambda (Walter 2007 sec. 5.1; Heitz 2014 eq. 72) is
    Lambda(a) = (exp(-a^2) - a sqrt(pi) erfc(a)) / (2 a sqrt(pi)),
and the visible projected area V = z (1 + Lambda) = z/2 + n E(b) with b = a^2 = z^2/n^2 and
    E(b) = (exp(-b) + sqrt(pi b) erf(sqrt(b))) / (2 sqrt(pi))
(a erf(a) is even, so E is an entire function of b; E(0) = 1/(2 sqrt(pi)), E ~ sqrt(b)/2 for large
b; both terms of V are positive, so V has no cancellation). G1 = z/V.

This script fits E(b) on [0, 3.625^2] by P(b)/Q(b) of degree (4, 4) with Q(0) = 1, minimising the
maximum relative error (linearised least squares with Lawson reweighting toward the minimax;
mpmath at 40 digits), rounds the coefficients to f32 and reports the relative error of the rounded
fit in exact arithmetic on a 2001-point grid. Output pasted into src/ndf/beckmann.rs (G1_P, G1_Q).

Usage (from the crate root): python3 tools/fit_beckmann_g1.py [M K]   (default 4 4; ~1-3 minutes)
Needs python3 with mpmath only (no numpy).
"""
import struct
import sys

import mpmath as mp

mp.mp.dps = 40
SQRT_PI = mp.sqrt(mp.pi)
END = mp.mpf(3.625) ** 2  # b = a^2 at the cut-off a = 3.625, from where G1 rounds to 1.0f


def e_of_b(b):
    b = mp.mpf(b)
    if b == 0:
        return 1 / (2 * SQRT_PI)
    a = mp.sqrt(b)
    return (mp.exp(-b) + a * SQRT_PI * mp.erf(a)) / (2 * SQRT_PI)


def f32(x):
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def poly(cs, x):
    return sum(c * x**j for j, c in enumerate(cs))


def fit(lo, hi, m, k, npts=400, iters=40):
    # Chebyshev-distributed points (dense at the ends, where minimax errors peak).
    xs = [(lo + hi) / 2 - (hi - lo) / 2 * mp.cos(mp.pi * (i + 0.5) / npts) for i in range(npts)]
    fs = [e_of_b(x) for x in xs]
    w = [mp.mpf(1)] * npts
    dprev = [mp.mpf(1)] * npts
    best = None
    nun = m + 1 + k
    for _ in range(iters):
        # Unknowns p0..pm, q1..qk; residual (P - f Q) / (f Q_prev) ~ the relative error.
        ata = mp.zeros(nun, nun)
        atb = mp.zeros(nun, 1)
        for x, fx, wi, dp in zip(xs, fs, w, dprev):
            s = 1 / (fx * dp)
            row = [x**j * s for j in range(m + 1)] + [-fx * x**j * s for j in range(1, k + 1)]
            for r in range(nun):
                atb[r] += wi * row[r] * fx * s
                for c in range(nun):
                    ata[r, c] += wi * row[r] * row[c]
        sol = mp.lu_solve(ata, atb)
        num = [sol[j] for j in range(m + 1)]
        den = [mp.mpf(1)] + [sol[m + 1 + j] for j in range(k)]
        errs = [abs(poly(num, x) / poly(den, x) / fx - 1) for x, fx in zip(xs, fs)]
        emax = max(errs)
        if best is None or emax < best[0]:
            best = (emax, num, den)
        dprev = [poly(den, x) for x in xs]
        tot = sum(wi * er for wi, er in zip(w, errs))
        w = [wi * er / tot for wi, er in zip(w, errs)]
    return best


def main():
    m, k = (int(sys.argv[1]), int(sys.argv[2])) if len(sys.argv) > 2 else (4, 4)
    emax, num, den = fit(mp.mpf(0), END, m, k)
    numr = [f32(c) for c in num]
    denr = [f32(c) for c in den]
    worst = max(abs(poly(numr, x) / poly(denr, x) / e_of_b(x) - 1) for x in (END * i / 2000 for i in range(2001)))
    print(f"// E(b) on [0, 3.625^2], degree ({m}, {k}): fit {mp.nstr(emax, 3)}, f32 coefficients {mp.nstr(worst, 3)}")
    print("const G1_P: [f32; %d] = [%s];" % (m + 1, ", ".join(repr(c) for c in numr)))
    print("const G1_Q: [f32; %d] = [%s];" % (k + 1, ", ".join(repr(c) for c in denr)))


if __name__ == "__main__":
    main()
