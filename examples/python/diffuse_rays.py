"""Diffuse rays on a mesh, made with NumPy: origins spread over the surface by area, directions
cosine-distributed about each triangle's normal (the lab's "diffuse" rays: incoherent)."""

import numpy as np


def diffuse_rays(vertices: np.ndarray, indices: np.ndarray, n: int, seed: int = 1):
    """(origins, directions) of shape (n, 3), float32, C-contiguous. Each direction is in the
    outer hemisphere (the side of the normal facing away from the mesh's centroid: meshes'
    winding is not reliably outward), and each origin sits a hair above the surface (1e-5 of
    the mesh's size) on that side, so that it does not hit its own triangle."""
    rng = np.random.default_rng(seed)
    p0, p1, p2 = (vertices[indices[:, k]].astype(np.float64) for k in range(3))
    cross = np.cross(p1 - p0, p2 - p0)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    keep = area > 0
    tri = rng.choice(np.flatnonzero(keep), size=n, p=area[keep] / area[keep].sum())
    # Uniform point on a triangle (Osada et al. 2002): sqrt of one uniform variate.
    r1, r2 = np.sqrt(rng.random(n)), rng.random(n)
    p = ((1 - r1)[:, None] * p0[tri] + (r1 * (1 - r2))[:, None] * p1[tri] + (r1 * r2)[:, None] * p2[tri])
    normal = cross[tri] / np.linalg.norm(cross[tri], axis=1, keepdims=True)
    outward = np.einsum("ij,ij->i", normal, p - vertices.mean(axis=0)) >= 0
    normal = np.where(outward[:, None], normal, -normal)
    # Cosine-weighted hemisphere (Malley's method) in a frame around the normal (Duff et al. 2017).
    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(0.0, 1 - u1))], axis=1)
    sign = np.where(normal[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (sign + normal[:, 2])
    b = normal[:, 0] * normal[:, 1] * a
    t = np.stack([1 + sign * normal[:, 0] ** 2 * a, sign * b, -sign * normal[:, 0]], axis=1)
    bt = np.stack([b, sign + normal[:, 1] ** 2 * a, -normal[:, 1]], axis=1)
    d = local[:, :1] * t + local[:, 1:2] * bt + local[:, 2:3] * normal
    size = np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0))
    o = p + normal * (1e-5 * size)
    return np.ascontiguousarray(o, dtype=np.float32), np.ascontiguousarray(d, dtype=np.float32)
