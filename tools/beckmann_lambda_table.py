#!/usr/bin/env python3
"""Generates the piecewise-polynomial table of k(a) = a Lambda(a) used by src/ndf/beckmann.rs.

Beckmann's Smith Lambda (Walter 2007 sec. 5.1; Heitz 2014 eq. 72) as a function of
a = 1/(alpha tan theta) is Lambda(a) = (exp(-a^2) - a sqrt(pi) erfc(a)) / (2 a sqrt(pi)), so

    k(a) = a Lambda(a) = (exp(-a^2) - a sqrt(pi) erfc(a)) / (2 sqrt(pi))

is an entire function (no pole near a = 0, unlike G1 or G1/a), decreasing from 1/(2 sqrt(pi)) at
a = 0 to ~2e-8 at a = 3.625. The crate evaluates G1 = z / (z + n k(a)) and V = z + n k(a).

On each of the SEGMENTS = 29 cells [i/8, (i+1)/8) of [0, 3.625) k is approximated, as a function of
the local coordinate t = 8a - i in [0, 1), by its degree-4 Chebyshev interpolant (mpmath.chebyfit,
evaluated at 40 digits), written in powers of t and rounded to f32. A 30th row of zeros gives
k = 0 for a >= 3.625 (where G1 rounds to 1.0f).

Prints the Rust table and, per cell, the error of the f32-rounded polynomial against k in exact
arithmetic, relative to h(a) = a + k(a) (what G1 = a / h and V = n h inherit), on a 200-point grid.

Usage (from the crate root): python3 tools/beckmann_lambda_table.py
Needs python3 with mpmath only (no numpy).
"""
import struct

import mpmath as mp

mp.mp.dps = 40
SQRT_PI = mp.sqrt(mp.pi)
SCALE = 8
DEGREE = 4
SEGMENTS = 29  # 29 / 8 = 3.625


def k(a):
    a = mp.mpf(a)
    return (mp.exp(-a * a) - a * SQRT_PI * mp.erfc(a)) / (2 * SQRT_PI)


def f32(x):
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def main():
    rows = []
    worst = mp.mpf(0)
    for i in range(SEGMENTS):
        a0 = mp.mpf(i) / SCALE
        poly = mp.chebyfit(lambda t: k(a0 + t / SCALE), [0, 1], DEGREE + 1)  # highest power first
        coeffs = [f32(c) for c in reversed(poly)]  # ascending powers of t
        err = mp.mpf(0)
        for j in range(201):
            t = mp.mpf(j) / 200
            a = a0 + t / SCALE
            approx = sum(mp.mpf(c) * t**p for p, c in enumerate(coeffs))
            err = max(err, abs(approx - k(a)) / (a + k(a)))
        worst = max(worst, err)
        rows.append((coeffs, err))
    print(f"// max error of the f32-rounded table, relative to a + k(a): {mp.nstr(worst, 3)}")
    print(f"const K_TABLE: [[f32; {DEGREE + 1}]; {SEGMENTS + 1}] = [")
    for i, (coeffs, err) in enumerate(rows):
        print(f"    [{', '.join(repr(c) for c in coeffs)}], // [{i}/8, {i + 1}/8): {mp.nstr(err, 2)}")
    print(f"    [{', '.join(['0.0'] * (DEGREE + 1))}], // a >= 29/8: k = 0")
    print("];")


if __name__ == "__main__":
    main()
