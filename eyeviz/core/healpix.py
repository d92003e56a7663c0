"""HEALPix in RING order for any nside, vectorised (Gorski et al. 2005, section 4).

The formulas are healpy's convention (``ang2pix(nside, theta, phi)`` with z = cos(theta)),
written out for every nside, not only powers of two: the paper's m = 720 facets on the
equator is nside 180. Pixels are also addressed by (face, ix, iy), the 12 base cells and
the integer coordinates inside them, because the closure of a pixel is the image of the
unit square [ix, ix+1] x [iy, iy+1] / nside of its face under :func:`xyf2vec` (edges are
the lines x = const and y = const): that is how centres, vertices and boundaries are
computed here and how the exact lit sets of :mod:`eyeviz.core.geometry3d` walk cell edges.

Only numpy; int64 indices. nside up to 2**20 keeps every index and product exact.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "npix",
    "nrings",
    "ang2pix_ring",
    "vec2pix_ring",
    "pix2ring",
    "ring_info",
    "ring_z",
    "ring_z_range",
    "pix2xyf",
    "xyf2vec",
    "xyf2loc",
    "centers",
    "boundaries",
    "JRLL",
    "JPLL",
]

#: ring of a face's north corner in units of nside (Gorski et al. 2005, Table 1)
JRLL = np.array([2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4], np.int64)
#: longitude of a face's centre in units of pi/4
JPLL = np.array([1, 3, 5, 7, 0, 2, 4, 6, 1, 3, 5, 7], np.int64)

_HALF_PI = 0.5 * math.pi
_TWO_PI = 2.0 * math.pi


def npix(nside: int) -> int:
    """Number of pixels on the sphere, 12 * nside**2."""
    return 12 * int(nside) ** 2


def nrings(nside: int) -> int:
    """Number of iso-latitude rings, 4 * nside - 1 (rings 1 .. 4 nside - 1)."""
    return 4 * int(nside) - 1


def ang2pix_ring(nside: int, z, phi) -> np.ndarray:
    """RING index of the direction (z = cos(theta), longitude phi), healpy's ang2pix.

    Float64 evaluation of Gorski et al. (2005) Eq. (4)-(9) as healpy writes it
    (``T_Healpix_Base::loc2pix``): equatorial zone |z| <= 2/3 by the two edge-line
    indices jp, jm; polar caps by the same in the coordinates of the base cell.
    ``phi`` may be any real (taken mod 2 pi).
    """
    n = int(nside)
    z = np.asarray(z, dtype=np.float64)
    phi = np.asarray(phi, dtype=np.float64)
    z, phi = np.broadcast_arrays(z, phi)
    za = np.abs(z)
    tt = np.mod(phi * (1.0 / _HALF_PI), 4.0)
    tt = np.where(tt >= 4.0, 0.0, tt)
    out = np.empty(z.shape, np.int64)
    eq = za <= 2.0 / 3.0
    # equatorial zone
    t1 = n * (0.5 + tt[eq])
    t2 = n * z[eq] * 0.75
    jp = np.floor(t1 - t2).astype(np.int64)
    jm = np.floor(t1 + t2).astype(np.int64)
    ir = n + 1 + jp - jm  # 1 .. 2n+1, counted from z = 2/3
    kshift = 1 - (ir & 1)
    ip = ((jp + jm - n + kshift + 1 + 8 * n) >> 1) % (4 * n)
    out[eq] = 2 * n * (n - 1) + (ir - 1) * 4 * n + ip
    # polar caps
    po = ~eq
    ttp, zp, zap = tt[po], z[po], za[po]
    tp = ttp - np.floor(ttp)
    tmp = n * np.sqrt(3.0 * (1.0 - zap))
    jp = np.floor(tp * tmp).astype(np.int64)
    jm = np.floor((1.0 - tp) * tmp).astype(np.int64)
    ir = jp + jm + 1  # ring counted from the nearest pole
    ip = np.minimum(np.floor(ttp * ir).astype(np.int64), 4 * ir - 1)
    out[po] = np.where(zp > 0, 2 * ir * (ir - 1) + ip, 12 * n * n - 2 * ir * (ir + 1) + ip)
    return out


def vec2pix_ring(nside: int, x, y, z) -> np.ndarray:
    """RING index of the direction of the vector (x, y, z) (not necessarily unit).

    lon = atan2(y, x) mod 2 pi (0 at the poles), z / |v| the cosine of the colatitude.
    """
    x, y, z = np.broadcast_arrays(*(np.asarray(v, dtype=np.float64) for v in (x, y, z)))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore", under="ignore"):
        # scale by a power of two (exact) so the squares neither overflow nor underflow
        big = np.maximum(np.maximum(np.abs(x), np.abs(y)), np.abs(z))
        ex = np.frexp(big)[1]
        xs, ys, zs = (np.ldexp(v, -ex) for v in (x, y, z))
        r = np.sqrt(xs * xs + ys * ys + zs * zs)
        zc = np.where(r > 0, zs / r, 1.0)
    return ang2pix_ring(nside, np.clip(zc, -1.0, 1.0), np.arctan2(y, x))


def ring_info(nside: int, ring) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(first pixel, number of pixels, shifted) of rings 1 .. 4 nside - 1.

    ``shifted`` is True where the ring's first pixel centre lies at phi = pi / npix_ring
    (half a pixel from phi = 0), False where it lies at phi = 0; polar rings are shifted.
    """
    n = int(nside)
    i = np.asarray(ring, dtype=np.int64)
    north = i < n
    south = i > 3 * n
    k = np.where(north, i, np.where(south, 4 * n - i, n))
    num = 4 * k
    first = np.where(
        north,
        2 * i * (i - 1),
        np.where(south, 12 * n * n - 2 * k * (k + 1), 2 * n * (n - 1) + (i - n) * 4 * n),
    )
    shifted = north | south | (((i - n) & 1) == 0)
    return first, num, shifted


def pix2ring(nside: int, pix) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(ring number 1 .. 4 nside - 1, first pixel of the ring, pixels in it, shifted)."""
    n = int(nside)
    p = np.asarray(pix, dtype=np.int64)
    ncap = 2 * n * (n - 1)
    total = 12 * n * n
    north = p < ncap
    south = p >= total - ncap
    # isqrt in float64 is exact to +-1 for p < 2**53: fix up by one step each way
    rn = ((1 + _isqrt(1 + 2 * p)) >> 1).astype(np.int64)
    ps = np.maximum(total - p, 1)
    rs = ((1 + _isqrt(2 * ps - 1)) >> 1).astype(np.int64)
    req = (p - ncap) // (4 * n) + n
    ring = np.where(north, rn, np.where(south, 4 * n - rs, req))
    first, num, shifted = ring_info(n, ring)
    return ring, first, num, shifted


def _isqrt(v: np.ndarray) -> np.ndarray:
    r = np.floor(np.sqrt(v.astype(np.float64))).astype(np.int64)
    r = np.where(r * r > v, r - 1, r)
    r = np.where((r + 1) * (r + 1) <= v, r + 1, r)
    return r


def ring_z(nside: int, ring) -> np.ndarray:
    """z = cos(theta) of the pixel centres of a ring (and of its W/E vertices)."""
    n = int(nside)
    i = np.asarray(ring, dtype=np.float64)
    return _z_of_jr(i / n)


def _z_of_jr(jr):
    """z at the height jr (in units of nside rings): the rings' z as a function."""
    jr = np.asarray(jr, dtype=np.float64)
    return np.where(
        jr < 1,
        1.0 - jr * jr / 3.0,
        np.where(jr > 3, (4.0 - jr) ** 2 / 3.0 - 1.0, (2.0 - jr) * (2.0 / 3.0)),
    )


def ring_z_range(nside: int, ring) -> tuple[np.ndarray, np.ndarray]:
    """(z_min, z_max) of the closures of the pixels of a ring: the centres' z of the
    rings below and above (1 and -1 at the poles)."""
    i = np.asarray(ring, dtype=np.int64)
    n = int(nside)
    return _z_of_jr((i + 1) / n), _z_of_jr((i - 1) / n)


def pix2xyf(nside: int, pix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ix, iy, face) of RING pixels (healpy's ``ring2xyf``), any nside."""
    n = int(nside)
    p = np.asarray(pix, dtype=np.int64)
    ring, first, num, _ = pix2ring(n, p)
    iphi = p - first + 1  # 1-based in its ring
    north = ring < n
    south = ring > 3 * n
    nr = np.where(north, ring, np.where(south, 4 * n - ring, n))
    kshift = np.where(north | south, 0, (ring + n) & 1)
    # equatorial faces
    ire = ring - n + 1
    irm = 2 * n + 2 - ire
    ifm = (iphi - (ire >> 1) + n - 1) // n
    ifp = (iphi - (irm >> 1) + n - 1) // n
    face_eq = np.where(ifp == ifm, ifp | 4, np.where(ifp < ifm, ifp, ifm + 8))
    face = np.where(north, (iphi - 1) // nr, np.where(south, (iphi - 1) // nr + 8, face_eq)).astype(
        np.int64
    )
    irt = ring - (2 + (face >> 2)) * n + 1
    ipt = 2 * iphi - JPLL[face] * nr - kshift - 1
    ipt = np.where(ipt >= 2 * n, ipt - 8 * n, ipt)
    ix = (ipt - irt) >> 1
    iy = (-ipt - irt) >> 1
    return ix, iy, face


def xyf2loc(nside: int, x, y, face) -> tuple[np.ndarray, np.ndarray]:
    """(z, phi) of the point (x, y) of a face, x and y in pixel units (0 .. nside).

    Pixel (ix, iy) is the square [ix, ix+1] x [iy, iy+1]; healpy's ``xyf2loc``.
    """
    n = float(nside)
    fx = np.asarray(x, dtype=np.float64) / n
    fy = np.asarray(y, dtype=np.float64) / n
    face = np.asarray(face, dtype=np.int64)
    jr = JRLL[face] - fx - fy
    nr = np.where(jr < 1, jr, np.where(jr > 3, 4.0 - jr, 1.0))
    z = _z_of_jr(jr)
    t = JPLL[face] * nr + fx - fy
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(nr > 0, (0.25 * math.pi) * t / nr, 0.0)
    phi = np.mod(phi, _TWO_PI)
    return z, phi


def xyf2vec(nside: int, x, y, face) -> np.ndarray:
    """Unit vectors (..., 3) of the points (x, y) of a face (see :func:`xyf2loc`).

    sin(theta) is computed from the face coordinates, not from z, near the poles, so
    it keeps its relative precision there.
    """
    n = float(nside)
    fx = np.asarray(x, dtype=np.float64) / n
    fy = np.asarray(y, dtype=np.float64) / n
    face = np.asarray(face, dtype=np.int64)
    jr = JRLL[face] - fx - fy
    polar = (jr < 1) | (jr > 3)
    nr = np.where(jr < 1, jr, np.where(jr > 3, 4.0 - jr, 1.0))
    z = _z_of_jr(jr)
    # sin(theta) = sqrt(1 - z^2) = nr * sqrt((2 - nr^2 / 3) / 3) in the polar caps
    sth = np.where(
        polar, nr * np.sqrt(np.maximum(2.0 - nr * nr / 3.0, 0.0) / 3.0), np.sqrt(1.0 - z * z)
    )
    t = JPLL[face] * nr + fx - fy
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.where(nr > 0, (0.25 * math.pi) * t / nr, 0.0)
    return np.stack([sth * np.cos(phi), sth * np.sin(phi), z], axis=-1)


def centers(nside: int, pix=None) -> np.ndarray:
    """Unit vectors (..., 3) of pixel centres (all pixels when ``pix`` is None)."""
    n = int(nside)
    p = np.arange(npix(n), dtype=np.int64) if pix is None else np.asarray(pix, np.int64)
    ix, iy, f = pix2xyf(n, p)
    return xyf2vec(n, ix + 0.5, iy + 0.5, f)


def boundaries(nside: int, pix, step: int = 1) -> np.ndarray:
    """Unit vectors (..., 4 * step, 3) along the closed boundary of each pixel.

    Counter-clockwise seen from outside, starting at the north vertex: N, W, S, E
    corners, ``step`` points per edge (healpy's ``boundaries`` order).
    """
    if int(step) < 1:
        raise ValueError(f"step must be an integer >= 1, got {step!r}")
    n, s = int(nside), int(step)
    ix, iy, f = pix2xyf(n, np.asarray(pix, np.int64))
    t = np.arange(s) / s
    # N (1,1) -> W (0,1) -> S (0,0) -> E (1,0) -> back to N
    dx = np.concatenate([1 - t, np.zeros(s), t, np.ones(s)])
    dy = np.concatenate([np.ones(s), 1 - t, np.zeros(s), t])
    return xyf2vec(n, ix[..., None] + dx, iy[..., None] + dy, f[..., None])


def _ring_quarter(n: int, k):
    """Cells per quarter of ring k (0 and 4 nside are the poles: 0)."""
    return np.minimum(np.minimum(k, n), 4 * n - k)


def ring_sz(nside: int, k) -> tuple[np.ndarray, np.ndarray]:
    """(sin(theta), z) of ring k, k = 0 .. 4 nside (0 and 4 nside: the poles).

    The same formulas as :func:`xyf2vec` (sin(theta) from the ring height in the polar
    caps, so it keeps its relative precision there).
    """
    n = int(nside)
    k = np.asarray(k, dtype=np.int64)
    jr = k / n
    z = _z_of_jr(jr)
    nr = np.minimum(jr, 4.0 - jr)
    polar = (k < n) | (k > 3 * n)
    sth = np.where(
        polar, nr * np.sqrt(np.maximum(2.0 - nr * nr / 3.0, 0.0) / 3.0), np.sqrt(1.0 - z * z)
    )
    return sth, z


def vertex_lon(nside: int, ring, j) -> tuple[np.ndarray, ...]:
    """Longitudes of the N, W, S, E vertices of cell j (0-based) of ring ``ring``.

    Returns (L_N, u_N, L_W, L_E, u_i, L_S, u_S): integers L and units u with the
    longitude L * u (u = pi / (4 K), K the cells per quarter of the vertex's ring; 0 at
    a pole). W and E lie on the cell's own ring, N on ring - 1, S on ring + 1: every
    vertex of a cell of ring i lies on ring i - 1, i or i + 1 (Gorski et al. 2005, the
    face coordinates x + y are constant on a ring), at a multiple of half its spacing.
    """
    n = int(nside)
    i = np.asarray(ring, dtype=np.int64)
    j = np.asarray(j, dtype=np.int64)
    K = _ring_quarter(n, i)
    Kn = _ring_quarter(n, i - 1)
    Ks = _ring_quarter(n, i + 1)
    shifted = (i < n) | (i > 3 * n) | (((i - n) & 1) == 0)
    o2 = np.where(shifted, 0, -1)
    lw = 2 * j + o2
    f = j // K
    p = j - f * K
    # N: same quarter count -> the cell's centre longitude; one fewer (north cap) or one
    # more (south cap) -> the lattice of ring i - 1
    ln = np.where(Kn == K, lw + 1, np.where(Kn < K, 2 * Kn * f + 2 * p, 2 * Kn * f + 2 * p + 2))
    ls = np.where(Ks == K, lw + 1, np.where(Ks > K, 2 * Ks * f + 2 * p + 2, 2 * Ks * f + 2 * p))
    with np.errstate(divide="ignore"):
        un = np.where(Kn > 0, 0.25 * math.pi / np.maximum(Kn, 1), 0.0)
        us = np.where(Ks > 0, 0.25 * math.pi / np.maximum(Ks, 1), 0.0)
    ui = 0.25 * math.pi / K
    return ln, un, lw, lw + 2, ui, ls, us
