"""Closed-form images of the failure scenes that have one (scenes/failure/manifest.json,
"reference": {"kind": "closed_form", "model": ...}): a Lambertian plane y = 0 (albedo rho, no
specular layer: KHR_materials_specular factor 0) seen straight from above by an orthographic
camera whose frame spans model["view"] x and z, with image right = +X and image up = -Z, lit
directly by point lights, spot lights and emissive quads that face it. Nothing else is in the
scene, so light reflects once: a pixel's value is the average over its footprint of

    L(x) = rho / pi * E(x),

    point light (intensity I, W/sr, at p):   E = I cos(theta) / d^2
    spot light (also direction a, cone angles inner/outer): the same times KHR_lights_punctual's
        recommended falloff clamp((cos_d - cos_outer) / (cos_inner - cos_outer), 0, 1)^2 with
        cos_d = a . (x - p) / d (wavepath's kernels/lights/lights.h)
    emissive polygon (radiance Le, front toward the plane, wholly above it): Lambert's formula
        E = Le / 2 * sum_k theta_k n . unit(r_k x r_{k+1}),  r_k = v_k - x,
        theta_k the angle between r_k and r_{k+1}, n = +Y (the sign depends on the winding: the
        absolute value is taken, valid because every polygon is wholly on the plane's front side).

The footprint average is a 12 x 12 Gauss-Legendre product rule per pixel (camera rays sample the
pixel uniformly, a box filter). The integrand is smooth except across a spot cone's inner edge
(a kink), where the rule's error is ~1e-4 of the value on the few pixels the edge crosses: far
below the Monte Carlo error the tests resolve.
"""

import numpy as np


def _irradiance(model, x, z):
    """E at plane points (x, z) (arrays of equal shape), shape + (3,)."""
    p = np.stack([x, np.zeros_like(x), z], axis=-1)
    e = np.zeros(x.shape + (3,))
    for light in model.get("points", []):
        d = np.asarray(light["position"]) - p
        d2 = (d * d).sum(-1)
        cos = np.maximum(d[..., 1], 0.0) / np.sqrt(d2)
        e += (cos / d2)[..., None] * np.asarray(light["intensity"])
    for light in model.get("spots", []):
        d = np.asarray(light["position"]) - p
        d2 = (d * d).sum(-1)
        dist = np.sqrt(d2)
        cos = np.maximum(d[..., 1], 0.0) / dist
        a = np.asarray(light["direction"], dtype=np.float64)
        a = a / np.linalg.norm(a)
        cos_d = -(d @ a) / dist
        c_in, c_out = np.cos(light["inner"]), np.cos(light["outer"])
        scale = 1.0 / max(0.001, c_in - c_out)
        fall = np.clip((cos_d - c_out) * scale, 0.0, 1.0) ** 2
        e += (cos * fall / d2)[..., None] * np.asarray(light["intensity"])
    for q in model.get("quads", []):
        v = np.asarray(q["corners"], dtype=np.float64)
        acc = np.zeros(x.shape)
        for k in range(len(v)):
            r0 = v[k] - p
            r1 = v[(k + 1) % len(v)] - p
            c = np.cross(r0, r1)
            cn = np.linalg.norm(c, axis=-1)
            cos_t = (r0 * r1).sum(-1) / (np.linalg.norm(r0, axis=-1) * np.linalg.norm(r1, axis=-1))
            theta = np.arccos(np.clip(cos_t, -1.0, 1.0))
            acc += theta * c[..., 1] / cn
        e += (0.5 * np.abs(acc))[..., None] * np.asarray(q["radiance"])
    return e


def image(model, width, height, order=12):
    """The (height, width, 3) image, top row first."""
    (x0, x1), (z0, z1) = model["view"]["x"], model["view"]["z"]
    nodes, weights = np.polynomial.legendre.leggauss(order)
    t = 0.5 * (nodes + 1.0)  # nodes on [0, 1]
    w = 0.5 * weights
    px = np.arange(width)[:, None] + t[None, :]    # (width, order) pixel coordinates
    py = np.arange(height)[:, None] + t[None, :]   # row 0 at the top = -Z edge (image up is -Z)
    xs = x0 + (x1 - x0) * px / width
    zs = z0 + (z1 - z0) * py / height
    X = xs[None, :, None, :]  # (1, width, 1, order)
    Z = zs[:, None, :, None]  # (height, 1, order, 1)
    X, Z = np.broadcast_arrays(X, Z)
    e = _irradiance(model, X, Z)  # (height, width, order, order, 3)
    e = np.einsum("hwijc,i,j->hwc", e, w, w)
    return np.asarray(model["albedo"]) / np.pi * e
