#!/usr/bin/env python3
"""Writes kernels/bsdf/sheen_table.h: the directional albedo E(mu, roughness) of the KHR_materials_sheen
lobe (kernels/bsdf/sheen.h, sheen colour 1) that the albedo-scaling layering looks up,

    E(mu) = integral over the hemisphere of D(h) V(wo, wi) cos(theta_i) d omega_i,  n.wo = mu,

on a grid uniform in (cbrt(mu), sqrt(roughness)), roughness from WP_SHEEN_ROUGHNESS_MIN (read from
kernels/bsdf/sheen.h) to 1. Pure Python, float64. Run from the repository root:
python3 tools/generators/gen_sheen_table.py (about 20 s).

Quadrature. With dw_i = d(cos theta_i) d phi and V cos_i = G / (4 mu), E = 1 / (4 mu) times the
integral of D(h) G(mu, cos_i) over cos_i in [0, 1] and phi. cos_i: composite Gauss-Legendre on
panels graded geometrically toward 0 (decades down to 1e-14: Lambda(cos_i) has cos_i^c, c ~ 0.17,
inside an exponential there), toward cos_i = mu from both sides (ratio 4, down to 1e-10 of the
distance: wi = the mirror direction of wo gives h = n, where D's sin^(1/alpha) has its cone
point) and broken at 0.5 (Lambda's two branches meet there with a jump in the second
derivative). phi: psi = pi - phi over [0, pi] (the integrand is even in phi), composite
Gauss-Legendre on quarters of [0, pi] and on panels graded geometrically (ratio 4) from pi/4 down
to the width of the dip of D near psi = 0, where h turns toward n. sin^2(theta_h) is formed from
|n x (wo + wi)|^2 and |wo + wi|^2 written as sums of non-negative terms, so it keeps its relative
precision at every angle. Each entry is computed with 8 and with 6 nodes per panel (both axes);
the difference bounds the 6-node error and so, generously, the 8-node one (the error falls
geometrically with the node count): its maximum is the QUAD_ERROR written to the header, and
tests/test_sheen.cpp checks every entry against an independent quadrature in h.

The mu = 0 column. E has no limit at mu = 0: the fitted Lambda is finite at cos = 0 (exp(a + e) <=
7.7e8), so G -> 1 / (1 + Lambda(0) + Lambda(cos_i)) stays positive and E ~ 1 / (4 mu (1 + ...))
grows without bound (past 1 below mu ~ 1e-6 at every roughness, past 26 at 1e-9); a physical
Smith Lambda grows like 1 / mu and keeps E finite. E's minimum over small mu lies between 3e-5
and 1e-4; at mu_1 = 1/31^3 = 3.4e-5 E is within 2.5% of it, and below mu_1 E rises, by 5-12% at
1e-5 and then without bound. The table is flat below mu_1: column 0 repeats column 1.

Interpolation. The grid's coordinates follow E's shape: features of width ~roughness in mu and a
sharp rise toward small mu (cube root), a ~1 / roughness growth at small roughness (square root).
The error of bilinear interpolation is measured at every cell's centre and edge midpoints (with
the 5-node rule, within 3e-6 of the 8-node one) and written to the header, rounded up from 1.25
times the largest, for two parts of the table: the first cell above the flat one, mu in
[mu_1, mu_2 = 8 / 31^3 = 2.7e-4], where E's dip between the fit's divergence and the rise toward
larger mu is a few hundredths deep (WP_SHEEN_TABLE_INTERP_ERROR_GRAZING), and mu >= mu_2
(WP_SHEEN_TABLE_INTERP_ERROR); the header also gives the largest error where E <= 1 (roughness
>= 0.26), which is four times smaller. tests/test_sheen.cpp checks the bounds at random points.
For comparison, during the design (400 random points, mu >= 1e-4, 32 x 32 each): 7.9e-3 for
these coordinates, 6.6e-2 for (sqrt(mu), roughness) and 0.25 for (mu, roughness).
"""

import math
import re
import sys
import textwrap
import time

N_MU = 32
N_R = 32
MU_FLAT = 1.0 / (N_MU - 1) ** 3  # below this mu the table is flat (docstring)

# Conty Estevez and Kulla's fit (the extension's l(x)): (value at alpha 1, value at alpha 0).
FIT = ((21.5473, 25.3245), (3.82987, 3.32435), (0.19823, 0.16801), (-1.97760, -1.27393),
       (-4.32054, -4.85967))


def roughness_min():
    text = open("kernels/bsdf/sheen.h").read()
    m = re.search(r"#define WP_SHEEN_ROUGHNESS_MIN ([0-9.eE+-]+)f", text)
    if not m:
        sys.exit("gen_sheen_table.py: WP_SHEEN_ROUGHNESS_MIN not found in kernels/bsdf/sheen.h")
    return float(m.group(1))


def node_mu(i):
    return (i / (N_MU - 1)) ** 3


def node_roughness(j, r_min):
    s0 = math.sqrt(r_min)
    return (s0 + (1.0 - s0) * j / (N_R - 1)) ** 2


def fit(alpha):
    t = (1.0 - alpha) ** 2
    return [p * (1.0 - t) + q * t for p, q in FIT]


def lam(x, f):
    def l(y):
        a, b, c, d, e = f
        return a / (1.0 + b * y ** c) + d * y + e
    return math.exp(l(x)) if x < 0.5 else math.exp(2.0 * l(0.5) - l(1.0 - x))


def gauss_legendre(n):
    """Nodes and weights on [-1, 1] (Newton on P_n from Tricomi's initial guesses)."""
    nodes, weights = [], []
    for k in range(1, n + 1):
        x = math.cos(math.pi * (k - 0.25) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for m in range(2, n + 1):
                p0, p1 = p1, ((2 * m - 1) * x * p1 - (m - 1) * p0) / m
            dp = n * (x * p1 - p0) / (x * x - 1.0)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-16:
                break
        nodes.append(x)
        weights.append(2.0 / ((1.0 - x * x) * dp * dp))
    return list(zip(nodes, weights))


RULES = {n: gauss_legendre(n) for n in (5, 6, 8)}


def cos_panels(mu):
    b = {0.0, 0.5, 1.0, mu}
    b.update(10.0 ** e for e in range(-14, 0))
    d = 0.5
    while d > 1e-10:
        b.update(p for p in (mu - d * mu, mu + d * (1.0 - mu)) if 0.0 < p < 1.0)
        d /= 4.0
    return sorted(b)


def albedo(mu, alpha, n):
    """E(mu) at alpha with an n-node Gauss-Legendre rule per panel (module docstring)."""
    rule = RULES[n]
    f = fit(alpha)
    k = 0.5 / alpha
    scale = (2.0 + 1.0 / alpha) / (2.0 * math.pi) / (4.0 * mu)
    sin_o = math.sqrt(1.0 - mu * mu)
    g_o = 1.0 + lam(mu, f)
    total = 0.0
    panels = cos_panels(mu)
    for lo, hi in zip(panels[:-1], panels[1:]):
        half = 0.5 * (hi - lo)
        for x, w in rule:
            ci = lo + half * (1.0 + x)
            si = math.sqrt(1.0 - ci * ci)
            # |wo + wi|^2 = (mu + ci)^2 + (so - si)^2 + 2 so si (1 + cos phi); the horizontal part
            # (so - si)^2 + 2 so si (1 + cos phi) is |n x (wo + wi)|^2.
            vert = (mu + ci) ** 2
            ds = (ci * ci - mu * mu) / (sin_o + si)
            base, amp = ds * ds, 4.0 * sin_o * si  # 2 so si (1 + cos phi) = amp sin^2(psi / 2)
            dip = math.sqrt((vert + base) / amp) if amp > 0.0 else math.pi
            edges = [math.pi * q / 4.0 for q in range(5)]
            q = math.pi / 4.0
            while q > max(0.25 * dip, 1e-12):
                q *= 0.25
                edges.append(q)
            edges.sort()
            inner = 0.0
            for a, b in zip(edges[:-1], edges[1:]):
                h = 0.5 * (b - a)
                for y, v in rule:
                    sn = math.sin(0.5 * (a + h * (1.0 + y)))
                    horiz = base + amp * sn * sn
                    if horiz > 0.0:
                        inner += h * v * math.exp(k * math.log(horiz / (horiz + vert)))
            total += half * w * 2.0 * inner / (g_o + lam(ci, f))
    return scale * total


def round_up(x):
    """The smallest 1, 2 or 5 times a power of ten that is >= x."""
    p = 10.0 ** math.floor(math.log10(x))
    for m in (1, 2, 5, 10):
        if m * p >= x:
            return m * p


def literal(x):
    text = f"{x:.9g}"
    if "." not in text and "e" not in text:
        text += ".0"
    return text + "f"


def bilinear(table, x, y):
    i, j = min(int(x), N_MU - 2), min(int(y), N_R - 2)
    fx, fy = x - i, y - j
    e0 = table[j][i] * (1 - fx) + table[j][i + 1] * fx
    e1 = table[j + 1][i] * (1 - fx) + table[j + 1][i + 1] * fx
    return e0 * (1 - fy) + e1 * fy


def main():
    start = time.time()
    r_min = roughness_min()
    table, quad_error, worst_entry = [], 0.0, None
    for j in range(N_R):
        alpha = node_roughness(j, r_min) ** 2
        row = [0.0]
        for i in range(1, N_MU):
            e8 = albedo(node_mu(i), alpha, 8)
            e6 = albedo(node_mu(i), alpha, 6)
            if abs(e8 - e6) > quad_error:
                quad_error, worst_entry = abs(e8 - e6), (i, j)
            row.append(e8)
        row[0] = row[1]  # flat below mu_1 (docstring)
        table.append(row)
    # [max error, (mu, roughness) where] for the first cell above the flat one, for the rest, and
    # for the rest where E <= 1 (roughness >= 0.26: tests/test_sheen.cpp): at every cell's centre
    # and the midpoints of its edges, in table coordinates (x, y).
    interp = {"grazing": [0.0, None], "rest": [0.0, None], "physical": [0.0, None]}
    s0 = math.sqrt(r_min)
    points = [(i + 0.5, j + 0.5) for i in range(1, N_MU - 1) for j in range(N_R - 1)]
    points += [(i + 0.5, j) for i in range(1, N_MU - 1) for j in range(N_R)]
    points += [(i, j + 0.5) for i in range(1, N_MU) for j in range(N_R - 1)]
    for x, y in points:
        mu, r = (x / (N_MU - 1)) ** 3, (s0 + (1.0 - s0) * y / (N_R - 1)) ** 2
        err = abs(bilinear(table, x, y) - albedo(mu, r * r, 5))
        parts = ["grazing"] if x < 2 else ["rest", "physical"] if r >= 0.26 else ["rest"]
        for part in parts:
            if err > interp[part][0]:
                interp[part] = [err, (mu, r)]
    e_max = max(max(row) for row in table)
    quad_bound = round_up(max(10.0 * quad_error, 1e-9))
    bounds = {k: round_up(1.25 * v[0]) for k, v in interp.items()}
    (e_rest, (mu_rest, r_rest)), (e_graz, (mu_graz, r_graz)) = interp["rest"], interp["grazing"]
    e_phys, (mu_phys, r_phys) = interp["physical"]
    rows, line = [], ""
    for v in (literal(v) for row in table for v in row):
        if line and len(line) + len(v) + 2 > 96:
            rows.append(line)
            line = ""
        line += (" " if line else "") + v + ","
    rows.append(line.rstrip(","))
    i, j = worst_entry
    comment = (
        "Generated by tools/generators/gen_sheen_table.py; do not edit. The directional albedo E(mu, "
        "roughness) of the KHR_materials_sheen lobe with colour 1 (kernels/bsdf/sheen.h): "
        "wp_sheen_albedo[j * NMU + i] holds E at mu = (i/(NMU-1))^3 and sheen roughness "
        "(sqrt(r_min) + (1 - sqrt(r_min)) j/(NR-1))^2, alpha = roughness^2, r_min = "
        f"WP_SHEEN_ROUGHNESS_MIN = {r_min:g}; column i = 0 (mu = 0, where E has no limit) "
        f"repeats column 1: the table is flat below mu = {MU_FLAT:.3g}. Quadrature error of the "
        f"entries: at most {quad_error:.1e} (the 6- against the 8-node rule; at mu = "
        f"{node_mu(i):.3g}, roughness {node_roughness(j, r_min):.3f}); bound used by the tests "
        "WP_SHEEN_TABLE_QUAD_ERROR. Bilinear interpolation error, measured at every cell's "
        "centre and edge midpoints (5-node rule, within 3e-6): for mu >= "
        f"{node_mu(2):.3g} at most {e_rest:.2e} (at mu = {mu_rest:.3g}, roughness "
        f"{r_rest:.3f}), bound WP_SHEEN_TABLE_INTERP_ERROR; there and for roughness >= 0.26, "
        f"where E <= 1, at most {e_phys:.2e} (at mu = {mu_phys:.3g}, roughness {r_phys:.3f}); "
        f"for mu in [{node_mu(1):.3g}, {node_mu(2):.3g}] at most {e_graz:.2e} (at mu = "
        f"{mu_graz:.3g}, roughness {r_graz:.3f}), bound WP_SHEEN_TABLE_INTERP_ERROR_GRAZING. "
        f"Largest entry {e_max:.4f}.")
    body = "\n    ".join(rows)
    with open("kernels/bsdf/sheen_table.h", "w") as out:
        out.write("/* " + "\n * ".join(textwrap.wrap(comment, 96, break_on_hyphens=False)) + " */\n")
        out.write(f"""#ifndef WP_SHEEN_TABLE_H
#define WP_SHEEN_TABLE_H

#define WP_SHEEN_TABLE_NMU {N_MU}
#define WP_SHEEN_TABLE_NR {N_R}
#define WP_SHEEN_TABLE_SQRT_RMIN {literal(math.sqrt(r_min))}
#define WP_SHEEN_TABLE_QUAD_ERROR {quad_bound:g}
#define WP_SHEEN_TABLE_INTERP_ERROR {bounds["rest"]:g}
#define WP_SHEEN_TABLE_INTERP_ERROR_GRAZING {bounds["grazing"]:g}

__constant float wp_sheen_albedo[WP_SHEEN_TABLE_NR * WP_SHEEN_TABLE_NMU] = {{
    {body}}};

#endif /* WP_SHEEN_TABLE_H */
""")
    print(f"kernels/bsdf/sheen_table.h: {N_MU} x {N_R}, quadrature error {quad_error:.1e}, "
          f"interpolation error {e_rest:.2e} (mu >= {node_mu(2):.3g}; {e_phys:.2e} where "
          f"E <= 1), {e_graz:.2e} below, largest entry {e_max:.4f}, "
          f"{time.time() - start:.1f} s")


if __name__ == "__main__":
    main()
