#!/usr/bin/env python3
"""Prints the coefficients of atan_poly (kernels/sampling/warps.h): atan(a) ~ a P(a^2) on [0, 1], P of
degree 8, fitted for the least largest absolute error by Lawson's iteratively reweighted least
squares on a dense grid (the weights converge to the minimax error's alternation points), in
double precision; then the fit's largest error in double and, with the coefficients rounded to
float, the largest error of Horner's scheme evaluated in float. Needs numpy. Run from the
repository root: python3 tools/generators/gen_atan_poly.py"""

import numpy as np

DEGREE = 8  # of P in a^2: a P(a^2) has degree 17


def fit(degree, iterations=400):
    grid = np.linspace(0.0, 1.0, 20001)[1:]
    cheb = 0.5 + 0.5 * np.cos(np.linspace(0.0, np.pi, 8001))
    a = np.unique(np.concatenate([grid, cheb[cheb > 0.0]]))
    s = a * a
    basis = np.stack([a * s**k for k in range(degree + 1)], axis=1)
    target = np.arctan(a)
    weights = np.full(a.shape, 1.0 / a.size)
    for _ in range(iterations):
        root = np.sqrt(weights)
        coef, *_ = np.linalg.lstsq(basis * root[:, None], target * root, rcond=None)
        err = np.abs(basis @ coef - target)
        weights = weights * err
        weights /= weights.sum()
    return coef, float(np.max(np.abs(basis @ coef - target)))


def horner_f32(coef, a):
    a = a.astype(np.float32)
    s = a * a
    p = np.full_like(a, coef[-1])
    for c in coef[-2::-1]:
        p = p * s + c
    return a * p


def main():
    coef, err = fit(DEGREE)
    coef32 = coef.astype(np.float32)
    a = np.linspace(0.0, 1.0, 4000001).astype(np.float32)
    err32 = np.max(np.abs(horner_f32(coef32, a).astype(np.float64) - np.arctan(a.astype(np.float64))))
    print(f"largest error of the fit (double): {err:.3g}")
    print(f"largest error in float (coefficients rounded, Horner in float): {err32:.3g}")
    print("coefficients of a^1, a^3, ..., a^17:")
    for c in coef32:
        print(f"  {float(c):.9e}f")


if __name__ == "__main__":
    main()
