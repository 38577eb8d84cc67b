#!/usr/bin/env python3
"""Coefficients of the lane kernel's G(-t) in src/glint/mixture/blocks.rs (`ramp_neg_lanes`).

G(-t) = phi(t) h(t), h(t) = 1 - t R(t) (R = Q/phi, Mills' ratio), is written as
tau^2 exp(P(tau) - t^2/2) / sqrt(2 pi) with tau = 1/(1 + t/C). P is a degree-9 polynomial in
u = tau - 0.6, fitted to ln(h / tau^2) over tau in [1/(1 + 16/C), 1] (t in [0, 16]) by weighted
least squares in the Chebyshev basis with Lawson's reweighting toward the minimax fit.

Reference values of h: the erfc form below t = 3 (cancellation ~t^2 * 1e-16), Laplace's continued
fraction R = 1/(t + 1/(t + 2/(t + ...))) above, written as h = K/(t + K), K = 1/(t + 2/(t + ...)),
so that 1 - tR never cancels. Pure Python (math.erfc), no dependencies.

Run: python3 tools/fit_mixture_ramp.py   (prints the maximum fit error and the coefficients)
"""
import math

C = 4.0
DEG = 9
MID = 0.6
SQRT_2PI = math.sqrt(2.0 * math.pi)


def h(t):
    if t <= 3.0:
        q = 0.5 * math.erfc(t / math.sqrt(2.0))
        phi = math.exp(-t * t / 2.0) / SQRT_2PI
        return 1.0 - t * q / phi
    f = t
    for k in range(2000, 1, -1):
        f = t + k / f
    k1 = 1.0 / f
    return k1 / (t + k1)


def target(tau):
    t = C * (1.0 / tau - 1.0)
    return math.log(h(t) / (tau * tau))


def cheb(n, x):
    out = [1.0, x]
    for _ in range(2, n + 1):
        out.append(2.0 * x * out[-1] - out[-2])
    return out[: n + 1]


def solve(a, b):
    n = len(b)
    m = [row[:] + [bb] for row, bb in zip(a, b)]
    for i in range(n):
        p = max(range(i, n), key=lambda r: abs(m[r][i]))
        m[i], m[p] = m[p], m[i]
        for r in range(i + 1, n):
            f = m[r][i] / m[i][i]
            for c in range(i, n + 1):
                m[r][c] -= f * m[i][c]
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        x[i] = (m[i][n] - sum(m[i][j] * x[j] for j in range(i + 1, n))) / m[i][i]
    return x


def fit(lo, n_pts=400, iters=12):
    xs = [lo + (1 - lo) * (0.5 - 0.5 * math.cos(math.pi * (k + 0.5) / n_pts)) for k in range(n_pts)]
    ys = [target(x) for x in xs]
    u = lambda x: 2.0 * (x - lo) / (1.0 - lo) - 1.0
    w = [1.0] * n_pts
    for _ in range(iters):
        a = [[0.0] * (DEG + 1) for _ in range(DEG + 1)]
        b = [0.0] * (DEG + 1)
        for x, y, wi in zip(xs, ys, w):
            t = cheb(DEG, u(x))
            for i in range(DEG + 1):
                b[i] += wi * t[i] * y
                for j in range(DEG + 1):
                    a[i][j] += wi * t[i] * t[j]
        coef = solve(a, b)
        errs = [abs(sum(c * ti for c, ti in zip(coef, cheb(DEG, u(x)))) - y) for x, y in zip(xs, ys)]
        w = [wi * (e + 1e-300) for wi, e in zip(w, errs)]
        s = sum(w)
        w = [wi / s * n_pts for wi in w]
    return coef, max(errs)


def to_shifted_monomial(coef, lo):
    # sum c_k T_k(p x + q) as a polynomial in x, then in x - MID.
    p, q = 2.0 / (1.0 - lo), -2.0 * lo / (1.0 - lo) - 1.0
    ts = [[1.0], [q, p]]
    for k in range(2, DEG + 1):
        new = [0.0] * (k + 1)
        for i, c in enumerate(ts[-1]):
            new[i] += 2 * q * c
            new[i + 1] += 2 * p * c
        for i, c in enumerate(ts[-2]):
            new[i] -= c
        ts.append(new)
    m = [0.0] * (DEG + 1)
    for c, t in zip(coef, ts):
        for i, v in enumerate(t):
            m[i] += c * v
    out = [0.0] * (DEG + 1)
    for i, c in enumerate(m):
        for k in range(i + 1):
            out[k] += c * math.comb(i, k) * MID ** (i - k)
    return out


if __name__ == "__main__":
    lo = 1.0 / (1.0 + 16.0 / C)
    coef, err = fit(lo)
    print(f"tau in [{lo}, 1], degree {DEG}: max |P - ln(h/tau^2)| = {err:.3e}")
    for c in to_shifted_monomial(coef, lo):
        print(repr(c))
