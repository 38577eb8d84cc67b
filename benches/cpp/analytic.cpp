// Scalar C++ transcriptions of the analytic microfacet core of pbrt (v4 for GGX and Fresnel, v3 for
// Beckmann, which v4 dropped) and Mitsuba 3, timed the way `benches/ndf.rs` and
// `benches/fresnel.rs` time the crate in their table mode (BRDF_TABLE=1): the same inputs (same
// generator, checked by a printed hash), batches of 1024 independent calls whose results are
// stored, every input component passed through an optimisation barrier, minimum and median over
// ROUNDS x BATCHES batches.
//
// Written for this comparison from the published formulas (pbrt-v4 `util/scattering.h`,
// pbrt-v3 `core/microfacet.cpp`, Mitsuba 3 `render/microfacet.h` and `render/fresnel.h`); the
// numerical routines are reduced to what the timed call executes (no spectral types, no SIMD
// packets). Build and run with `benches/cpp/run.sh` (see README.md there).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvSqrtPi = 0.56418958354775628695f;

struct V3 {
    float x, y, z;
};
struct V2 {
    float x, y;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator*(float s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline V3 normalize(V3 v) { return (1.0f / std::sqrt(dot(v, v))) * v; }
inline float sqr(float x) { return x * x; }
inline float safe_sqrt(float x) { return std::sqrt(std::max(x, 0.0f)); }
inline float clampf(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }

// A register-only optimisation barrier (the Rust side's `opaque`): the value passes through an empty
// asm in an SSE register, so the compiler can neither vectorise across calls nor hoist work out of
// the loop, and nothing is stored or reloaded. A barrier with a memory clobber (Rust's black_box,
// benchmark::DoNotOptimize) costs a store and reload per value, and LLVM and GCC pay for it
// differently.
inline float opaque(float v) {
    asm volatile("" : "+x"(v));
    return v;
}
inline V3 opaque3(V3 v) { return {opaque(v.x), opaque(v.y), opaque(v.z)}; }
inline V2 opaque2(V2 v) { return {opaque(v.x), opaque(v.y)}; }

// ---------------------------------------------------------------- inputs (same as the Rust side)
struct SplitMix {
    uint64_t s;
    uint64_t next() {
        uint64_t z = (s += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    float f() { return float(next() >> 40) * (1.0f / 16777216.0f); }
};

constexpr int N = 1024;
// Blocks of N inputs in the pool; batch k uses block k mod g_pool (table_common.rs says why: a
// repeated block lets the branch predictor learn every data-dependent branch). argv[3], default 16.
int g_pool = 16;

struct Inputs {
    std::vector<V3> w, m;
    std::vector<V2> u;
    std::vector<float> cos_signed, cos_unit;
};

Inputs make_inputs(float alpha) {
    Inputs in;
    SplitMix rng{1};
    const int n = N * g_pool;
    for (int i = 0; i < n; ++i) {
        float a = rng.f(), b = rng.f();
        float r = std::sqrt(a), phi = 6.28318548f * b;
        in.w.push_back({r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(1.0f - a, 1e-6f))});
    }
    for (V3 w : in.w) in.m.push_back(normalize({alpha * w.x, alpha * w.y, w.z}));
    for (int i = 0; i < n; ++i) {
        float a = rng.f(), b = rng.f();
        in.u.push_back({a, b});
    }
    for (int i = 0; i < n; ++i) in.cos_signed.push_back(2.0f * rng.f() - 1.0f);
    for (int i = 0; i < n; ++i) in.cos_unit.push_back(rng.f());
    return in;
}

uint64_t hash_inputs(const Inputs& in) {
    uint64_t h = 1469598103934665603ull;
    auto mix = [&](float v) {
        uint32_t b;
        std::memcpy(&b, &v, 4);
        h = (h ^ b) * 1099511628211ull;
    };
    for (size_t i = 0; i < in.w.size(); ++i) {
        mix(in.w[i].x), mix(in.w[i].y), mix(in.w[i].z);
        mix(in.m[i].x), mix(in.m[i].y), mix(in.m[i].z);
        mix(in.u[i].x), mix(in.u[i].y);
        mix(in.cos_signed[i]), mix(in.cos_unit[i]);
    }
    return h;
}

// ---------------------------------------------------------------- shared trigonometry (pbrt)
inline float cos2_theta(V3 w) { return w.z * w.z; }
inline float sin2_theta(V3 w) { return std::max(0.0f, 1.0f - cos2_theta(w)); }
inline float sin_theta(V3 w) { return std::sqrt(sin2_theta(w)); }
inline float tan_theta(V3 w) { return sin_theta(w) / w.z; }
inline float tan2_theta(V3 w) { return sin2_theta(w) / cos2_theta(w); }
inline float cos_phi(V3 w) {
    float s = sin_theta(w);
    return s == 0 ? 1 : clampf(w.x / s, -1, 1);
}
inline float sin_phi(V3 w) {
    float s = sin_theta(w);
    return s == 0 ? 0 : clampf(w.y / s, -1, 1);
}

// ---------------------------------------------------------------- GGX, pbrt-v4
struct PbrtGgx {
    float ax, ay;
    float D(V3 wm) const {
        float t2 = tan2_theta(wm);
        if (std::isinf(t2)) return 0;
        float cos4 = sqr(cos2_theta(wm));
        if (cos4 < 1e-16f) return 0;
        float e = t2 * (sqr(cos_phi(wm) / ax) + sqr(sin_phi(wm) / ay));
        return 1 / (kPi * ax * ay * cos4 * sqr(1 + e));
    }
    float Lambda(V3 w) const {
        float t2 = tan2_theta(w);
        if (std::isinf(t2)) return 0;
        float a2 = sqr(cos_phi(w) * ax) + sqr(sin_phi(w) * ay);
        return (std::sqrt(1 + a2 * t2) - 1) / 2;
    }
    float G1(V3 w) const { return 1 / (1 + Lambda(w)); }
    float PDF(V3 w, V3 wm) const { return G1(w) / std::abs(w.z) * D(wm) * std::abs(dot(w, wm)); }
    V3 Sample(V3 w, V2 u) const {
        V3 wh = normalize({ax * w.x, ay * w.y, w.z});
        if (wh.z < 0) wh = -1.0f * wh;
        V3 t1 = (wh.z < 0.99999f) ? normalize(cross({0, 0, 1}, wh)) : V3{1, 0, 0};
        V3 t2 = cross(wh, t1);
        float r = std::sqrt(u.x), th = 2 * kPi * u.y;
        V2 p{r * std::cos(th), r * std::sin(th)};
        float h = std::sqrt(1 - sqr(p.x));
        float s = (1 + wh.z) / 2;
        p.y = (1 - s) * h + s * p.y;
        float pz = std::sqrt(std::max(0.0f, 1 - sqr(p.x) - sqr(p.y)));
        V3 nh = p.x * t1 + p.y * t2 + pz * wh;
        return normalize({ax * nh.x, ay * nh.y, std::max(1e-6f, nh.z)});
    }
};

// ---------------------------------------------------------------- Beckmann, pbrt-v3
// Abramowitz & Stegun 7.1.26, as pbrt-v3's Erf.
inline float erf_as(float x) {
    const float a1 = 0.254829592f, a2 = -0.284496736f, a3 = 1.421413741f, a4 = -1.453152027f,
                a5 = 1.061405429f, p = 0.3275911f;
    float sign = x < 0 ? -1.0f : 1.0f;
    x = std::abs(x);
    float t = 1 / (1 + p * x);
    float y = 1 - (((((a5 * t + a4) * t) + a3) * t + a2) * t + a1) * t * std::exp(-x * x);
    return sign * y;
}
// Giles' single-precision erf^-1, as pbrt-v3's ErfInv and Mitsuba's erfinv.
inline float erfinv_giles(float x) {
    x = clampf(x, -.99999f, .99999f);
    float w = -std::log((1 - x) * (1 + x)), p;
    if (w < 5) {
        w = w - 2.5f;
        p = 2.81022636e-08f;
        p = 3.43273939e-07f + p * w;
        p = -3.5233877e-06f + p * w;
        p = -4.39150654e-06f + p * w;
        p = 0.00021858087f + p * w;
        p = -0.00125372503f + p * w;
        p = -0.00417768164f + p * w;
        p = 0.246640727f + p * w;
        p = 1.50140941f + p * w;
    } else {
        w = std::sqrt(w) - 3;
        p = -0.000200214257f;
        p = 0.000100950558f + p * w;
        p = 0.00134934322f + p * w;
        p = -0.00367342844f + p * w;
        p = 0.00573950773f + p * w;
        p = -0.0076224613f + p * w;
        p = 0.00943887047f + p * w;
        p = 1.00167406f + p * w;
        p = 2.83297682f + p * w;
    }
    return p * x;
}

struct PbrtBeckmann {
    float ax, ay;
    float D(V3 wh) const {
        float t2 = tan2_theta(wh);
        if (std::isinf(t2)) return 0;
        float cos4 = sqr(cos2_theta(wh));
        return std::exp(-t2 * (sqr(cos_phi(wh)) / sqr(ax) + sqr(sin_phi(wh)) / sqr(ay))) /
               (kPi * ax * ay * cos4);
    }
    // The rational fit of Walter et al. 2007, eq. 27 (via Λ).
    float Lambda(V3 w) const {
        float t = std::abs(tan_theta(w));
        if (std::isinf(t)) return 0;
        float alpha = std::sqrt(sqr(cos_phi(w)) * sqr(ax) + sqr(sin_phi(w)) * sqr(ay));
        float a = 1 / (alpha * t);
        if (a >= 1.6f) return 0;
        return (1 - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
    }
    float G1(V3 w) const { return 1 / (1 + Lambda(w)); }
    // pbrt-v3 has no visible pdf function; the v4 form D(w, wm) written with v3's Beckmann.
    float PDF(V3 w, V3 wm) const { return G1(w) / std::abs(w.z) * D(wm) * std::abs(dot(w, wm)); }
    static void Sample11(float cos_t, float u1, float u2, float* sx, float* sy) {
        if (cos_t > .9999f) {
            float r = std::sqrt(-std::log(1.0f - u1));
            float s = std::sin(2 * kPi * u2), c = std::cos(2 * kPi * u2);
            *sx = r * c;
            *sy = r * s;
            return;
        }
        float sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
        float tan_t = sin_t / cos_t, cot_t = 1 / tan_t;
        float a = -1, c = erf_as(cot_t);
        float sample_x = std::max(u1, 1e-6f);
        float theta = std::acos(cos_t);
        float fit = 1 + theta * (-0.876f + theta * (0.4265f - 0.0594f * theta));
        float b = c - (1 + c) * std::pow(1 - sample_x, fit);
        float norm = 1 / (1 + c + kInvSqrtPi * tan_t * std::exp(-cot_t * cot_t));
        int it = 0;
        while (++it < 10) {
            if (!(b >= a && b <= c)) b = 0.5f * (a + c);
            float inv = erfinv_giles(b);
            float value = norm * (1 + b + kInvSqrtPi * tan_t * std::exp(-inv * inv)) - sample_x;
            float deriv = norm * (1 - inv * tan_t);
            if (std::abs(value) < 1e-5f) break;
            if (value > 0) c = b; else a = b;
            b -= value / deriv;
        }
        *sx = erfinv_giles(b);
        *sy = erfinv_giles(2 * std::max(u2, 1e-6f) - 1);
    }
    V3 Sample(V3 wi, V2 u) const {
        V3 ws = normalize({ax * wi.x, ay * wi.y, wi.z});
        float sx, sy;
        Sample11(ws.z, u.x, u.y, &sx, &sy);
        float cp = cos_phi(ws), sp = sin_phi(ws);
        float tmp = cp * sx - sp * sy;
        sy = sp * sx + cp * sy;
        sx = tmp;
        return normalize({-ax * sx, -ay * sy, 1});
    }
};

// ---------------------------------------------------------------- Mitsuba 3 (GGX and Beckmann)
struct Mitsuba {
    bool beckmann;
    float au, av;
    float eval(V3 m) const {
        float c = m.z, c2 = c * c, r;
        if (beckmann)
            r = std::exp(-(sqr(m.x / au) + sqr(m.y / av)) / c2) / (kPi * au * av * sqr(c2));
        else
            r = 1 / (kPi * au * av * sqr(sqr(m.x / au) + sqr(m.y / av) + sqr(m.z)));
        return (r * c > 1e-20f) ? r : 0.0f;
    }
    float smith_g1(V3 v, V3 m) const {
        float xy2 = sqr(au * v.x) + sqr(av * v.y), t2 = xy2 / sqr(v.z), r;
        if (beckmann) {
            float a = 1 / std::sqrt(t2), a2 = a * a;
            r = (a >= 1.6f) ? 1.0f : (3.535f * a + 2.181f * a2) / (1 + 2.276f * a + 2.577f * a2);
        } else {
            r = 2 / (1 + std::sqrt(1 + t2));
        }
        if (xy2 == 0) r = 1;
        if (dot(v, m) * v.z <= 0) r = 0;
        return r;
    }
    float pdf(V3 wi, V3 m) const {
        float r = eval(m) * smith_g1(wi, m) * std::abs(dot(wi, m)) / wi.z;
        return (wi.z > 0 && m.z > 0) ? r : 0.0f;
    }
    V2 sample_visible_11(float cos_t, V2 u) const {
        if (beckmann) {
            float tan_t = safe_sqrt(1 - cos_t * cos_t) / cos_t, cot_t = 1 / tan_t;
            float a = -1, c = erf_as(cot_t);
            float ux = std::max(std::min(u.x, 1 - 1e-6f), 1e-6f);
            float uy = std::max(std::min(u.y, 1 - 1e-6f), 1e-6f);
            float theta = std::acos(cos_t);
            float fit = 1 + theta * (-0.876f + theta * (0.4265f - 0.0594f * theta));
            float b = c - (1 + c) * std::pow(1 - ux, fit);
            float norm = 1 / (1 + c + kInvSqrtPi * tan_t * std::exp(-sqr(cot_t)));
            int it = 0;
            while (true) {
                if (!(b >= a && b <= c)) b = .5f * (a + c);
                float inv = erfinv_giles(b);
                float value = norm * (1 + b + kInvSqrtPi * tan_t * std::exp(-sqr(inv))) - ux;
                float deriv = norm * (1 - inv * tan_t);
                if (++it > 2 && std::abs(value) < 1e-5f) break;
                if (it > 20) break;
                if (value > 0) c = b; else a = b;
                b -= value / deriv;
            }
            return {erfinv_giles(b), erfinv_giles(2 * uy - 1)};
        }
        // GGX: Heitz & d'Eon 2014's routine.
        float tan_t = safe_sqrt(1 - cos_t * cos_t) / cos_t;
        float g1 = 2 / (1 + safe_sqrt(1 + tan_t * tan_t));
        float A = 2 * u.x / g1 - 1, tmp = std::min(1 / (A * A - 1), 1e10f), B = tan_t;
        float D = safe_sqrt(B * B * tmp * tmp - (A * A - B * B) * tmp);
        float s1 = B * tmp - D, s2 = B * tmp + D;
        float sx = (A < 0 || s2 * tan_t > 1) ? s1 : s2;
        float S = u.y > .5f ? 1.0f : -1.0f, v = S * 2 * (u.y - .5f);
        float z = (v * (v * (v * -0.365728915865723f + 0.790235037209296f) - 0.424965825137544f) +
                   0.000152998850436920f) /
                  (v * (v * (v * (v * 0.169507819808272f - 0.397203533833404f) -
                             0.232500544458471f) + 1) - 0.539825872510702f);
        float sy = S * z * std::sqrt(1 + sx * sx);
        if (cos_t >= .99999f) {  // normal incidence: the plain sampler
            float r = std::sqrt(u.x / (1 - u.x)), ph = 2 * kPi * u.y;
            return {r * std::cos(ph), r * std::sin(ph)};
        }
        return {sx, sy};
    }
    V3 sample(V3 wi, V2 u) const {
        V3 w11 = normalize({au * wi.x, av * wi.y, wi.z});
        V2 s = sample_visible_11(w11.z, u);
        float st = safe_sqrt(1 - w11.z * w11.z);
        float cp = st > 0 ? w11.x / st : 1.0f, sp = st > 0 ? w11.y / st : 0.0f;
        V2 r{(cp * s.x - sp * s.y) * au, (sp * s.x + cp * s.y) * av};
        return normalize({-r.x, -r.y, 1});
    }
};

// ---------------------------------------------------------------- Fresnel
inline float pbrt_fr_dielectric(float cos_i, float eta) {
    cos_i = clampf(cos_i, -1, 1);
    if (cos_i < 0) {
        eta = 1 / eta;
        cos_i = -cos_i;
    }
    float sin2_i = 1 - sqr(cos_i), sin2_t = sin2_i / sqr(eta);
    if (sin2_t >= 1) return 1.f;
    float cos_t = safe_sqrt(1 - sin2_t);
    float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return (sqr(r_parl) + sqr(r_perp)) / 2;
}

inline float mitsuba_fresnel(float cos_i, float eta) {
    bool outside = cos_i >= 0;
    float rcp_eta = 1 / eta, eta_ti = outside ? rcp_eta : eta;
    float cos_t2 = 1 - (1 - cos_i * cos_i) * sqr(eta_ti);
    float ci = std::abs(cos_i), ct = safe_sqrt(cos_t2);
    bool matched = eta == 1, special = matched || ci == 0;
    float a_s = (ci - eta_ti * ct) / (ci + eta_ti * ct);
    float a_p = (ct - eta_ti * ci) / (ct + eta_ti * ci);
    float r = .5f * (sqr(a_s) + sqr(a_p));
    return special ? (matched ? 0.f : 1.f) : (cos_t2 <= 0 ? 1.f : r);
}

struct Cx {
    float re, im;
};
inline Cx operator+(Cx a, Cx b) { return {a.re + b.re, a.im + b.im}; }
inline Cx operator-(Cx a, Cx b) { return {a.re - b.re, a.im - b.im}; }
inline Cx operator*(Cx a, Cx b) { return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re}; }
inline Cx operator*(float s, Cx a) { return {s * a.re, s * a.im}; }
inline Cx operator/(Cx a, Cx b) {
    float s = 1 / (b.re * b.re + b.im * b.im);
    return {s * (a.re * b.re + a.im * b.im), s * (a.im * b.re - a.re * b.im)};
}
inline float norm(Cx a) { return a.re * a.re + a.im * a.im; }
// pbrt-v4's pstd::sqrt for complex numbers.
inline Cx csqrt(Cx z) {
    float n = std::sqrt(norm(z));  // |z| (pbrt uses abs = sqrt(norm) too)
    if (n == 0) return {0, 0};
    float t1 = std::sqrt(.5f * (n + std::abs(z.re))), t2 = .5f * z.im / t1;
    if (z.re >= 0) return {t1, t2};
    return {std::abs(t2), std::copysign(t1, z.im)};
}

inline float pbrt_fr_complex(float cos_i, Cx eta) {
    cos_i = clampf(cos_i, 0, 1);
    float sin2_i = 1 - cos_i * cos_i;
    Cx sin2_t = Cx{sin2_i, 0} / (eta * eta);
    Cx cos_t = csqrt(Cx{1, 0} - sin2_t);
    Cx r_parl = (cos_i * eta - cos_t) / (cos_i * eta + cos_t);
    Cx r_perp = (Cx{cos_i, 0} - eta * cos_t) / (Cx{cos_i, 0} + eta * cos_t);
    return (norm(r_parl) + norm(r_perp)) / 2;
}

inline float mitsuba_fresnel_conductor(float cos_i, float eta_r, float eta_i) {
    float c2 = cos_i * cos_i, s2 = 1 - c2, s4 = sqr(s2);
    float t1 = sqr(eta_r) - sqr(eta_i) - s2;
    float a2pb2 = safe_sqrt(sqr(t1) + 4 * sqr(eta_i) * sqr(eta_r));
    float a = safe_sqrt(.5f * (a2pb2 + t1));
    float term1 = a2pb2 + c2, term2 = 2 * cos_i * a;
    float rs = (term1 - term2) / (term1 + term2);
    float term3 = a2pb2 * c2 + s4, term4 = term2 * s2;
    float rp = rs * (term3 - term4) / (term3 + term4);
    return .5f * (rs + rp);
}

// Gold at 650 / 550 / 450 nm: the crate's ConductorFresnel::GOLD.
const float kGoldEta[3] = {0.156f, 0.424f, 1.383f};
const float kGoldK[3] = {3.602f, 2.472f, 1.916f};

// ---------------------------------------------------------------- timing
int g_rounds = 5, g_batches = 1000;

template <class F>
void time_it(const char* name, const char* variant, float alpha, F batch) {
    for (int i = 0; i < 200; ++i) batch((i % g_pool) * N);  // warm-up
    std::vector<double> ns;
    ns.reserve(g_rounds * g_batches);
    for (int r = 0; r < g_rounds; ++r)
        for (int b = 0; b < g_batches; ++b) {
            const int off = ((r * g_batches + b) % g_pool) * N;
            auto t0 = std::chrono::steady_clock::now();
            batch(off);
            auto t1 = std::chrono::steady_clock::now();
            ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / N);
        }
    std::sort(ns.begin(), ns.end());
    std::printf("%-24s %-8s %5.3f %8.2f %8.2f\n", name, variant, alpha, ns[0], ns[ns.size() / 2]);
    std::fflush(stdout);
}

template <class T>
void sink(std::vector<T>& out) {
    asm volatile("" : : "r"(out.data()) : "memory");
}

}  // namespace

int main(int argc, char** argv) {
    if (argc > 1) g_rounds = std::atoi(argv[1]);
    if (argc > 2) g_batches = std::atoi(argv[2]);
    if (argc > 3 && std::atoi(argv[3]) > 0) g_pool = std::atoi(argv[3]);
    std::vector<float> of(N);
    std::vector<V3> ov(N);
    std::printf("# function               variant  alpha   min_ns  median_ns\n");
    for (float alpha : {0.1f, 0.5f, 1.0f}) {
        Inputs in = make_inputs(alpha);
        std::printf("# inputs hash %016llx\n", (unsigned long long)hash_inputs(in));
        PbrtGgx pg{alpha, alpha};
        PbrtBeckmann pb{alpha, alpha};
        Mitsuba mg{false, alpha, alpha}, mb{true, alpha, alpha};
        const V3* w = in.w.data();
        const V3* m = in.m.data();
        const V2* u = in.u.data();
#define ROW(NAME, VARIANT, OUT, EXPR)                                      \
    time_it(NAME, VARIANT, alpha, [&](int off) {                            \
        for (int i = 0; i < N; ++i) {                                       \
            V3 wi = opaque3(w[off + i]), mi = opaque3(m[off + i]);            \
            V2 ui = opaque2(u[off + i]);                                     \
            (void)wi, (void)mi, (void)ui;                                   \
            OUT[i] = EXPR;                                                  \
        }                                                                   \
        sink(OUT);                                                          \
    })
        ROW("ggx/d", "pbrt4", of, pg.D(mi));
        ROW("ggx/d", "mitsuba3", of, mg.eval(mi));
        ROW("ggx/g1", "pbrt4", of, pg.G1(wi));
        ROW("ggx/g1", "mitsuba3", of, mg.smith_g1(wi, mi));
        ROW("ggx/pdf_visible", "pbrt4", of, pg.PDF(wi, mi));
        ROW("ggx/pdf_visible", "mitsuba3", of, mg.pdf(wi, mi));
        ROW("ggx/sample_visible", "pbrt4", ov, pg.Sample(wi, ui));
        ROW("ggx/sample_visible", "mitsuba3", ov, mg.sample(wi, ui));
        ROW("beckmann/d", "pbrt3", of, pb.D(mi));
        ROW("beckmann/d", "mitsuba3", of, mb.eval(mi));
        ROW("beckmann/g1", "pbrt3", of, pb.G1(wi));
        ROW("beckmann/g1", "mitsuba3", of, mb.smith_g1(wi, mi));
        ROW("beckmann/pdf_visible", "pbrt3", of, pb.PDF(wi, mi));
        ROW("beckmann/pdf_visible", "mitsuba3", of, mb.pdf(wi, mi));
        ROW("beckmann/sample_visible", "pbrt3", ov, pb.Sample(wi, ui));
        ROW("beckmann/sample_visible", "mitsuba3", ov, mb.sample(wi, ui));
#undef ROW
        if (alpha == 1.0f) {
            const float* cs = in.cos_signed.data();
            const float* cu = in.cos_unit.data();
            time_it("fresnel/dielectric", "pbrt4", 1.5f, [&](int off) {
                for (int i = 0; i < N; ++i) of[i] = pbrt_fr_dielectric(opaque(cs[off + i]), 1.5f);
                sink(of);
            });
            time_it("fresnel/dielectric", "mitsuba3", 1.5f, [&](int off) {
                for (int i = 0; i < N; ++i) of[i] = mitsuba_fresnel(opaque(cs[off + i]), 1.5f);
                sink(of);
            });
            time_it("fresnel/conductor", "pbrt4", 0, [&](int off) {
                for (int i = 0; i < N; ++i) {
                    float c = opaque(cu[off + i]);
                    V3 r;
                    r.x = pbrt_fr_complex(c, Cx{kGoldEta[0], kGoldK[0]});
                    r.y = pbrt_fr_complex(c, Cx{kGoldEta[1], kGoldK[1]});
                    r.z = pbrt_fr_complex(c, Cx{kGoldEta[2], kGoldK[2]});
                    ov[i] = r;
                }
                sink(ov);
            });
            time_it("fresnel/conductor", "mitsuba3", 0, [&](int off) {
                for (int i = 0; i < N; ++i) {
                    float c = opaque(cu[off + i]);
                    V3 r;
                    r.x = mitsuba_fresnel_conductor(c, kGoldEta[0], kGoldK[0]);
                    r.y = mitsuba_fresnel_conductor(c, kGoldEta[1], kGoldK[1]);
                    r.z = mitsuba_fresnel_conductor(c, kGoldEta[2], kGoldK[2]);
                    ov[i] = r;
                }
                sink(ov);
            });
        }
    }
    return 0;
}
