"""Normal modes of a solid railway wheel by axisymmetric finite elements with Fourier harmonics.

The wheel is a solid of revolution, so each mode has n nodal diameters and a shape over the
cross-section (r, z) (Thompson, J. Sound Vib. 161 (1993) 401-419, the method behind TWINS's
wheel model; Zienkiewicz & Taylor, The Finite Element Method, vol. 1, 5th ed. 2000, section 9.6,
for the semi-analytical harmonic formulation). For harmonic n the displacements are

    u_r = U_r(r, z) cos n theta,  u_theta = U_theta(r, z) sin n theta,  u_z = U_z(r, z) cos n theta,

and the strains (e_r, e_theta, e_z, g_rz, g_rtheta, g_thetaz) follow as

    e_r = U_r,r   e_theta = (U_r + n U_theta) / r   e_z = U_z,z   g_rz = U_r,z + U_z,r
    g_rtheta = U_theta,r - (U_theta + n U_r) / r     g_thetaz = U_theta,z - n U_z / r,

each times cos or sin n theta. Integrating over theta gives pi (n >= 1) or 2 pi (n = 0, without
U_theta) times the cross-section integrals, so the modes are normalised to unit generalised mass
of the whole wheel and their values at theta = 0 are physical. The cross-section is meshed with
9-node Lagrange rectangles (3 x 3 Gauss points, free of shear locking in the web); the bore is
clamped to a rigid axle, so the wheelset's rigid-body motion is the unsprung mass of
models.track.wheel_receptance and these are the flexible modes added to it.

The cross-section (``WheelSection``) is a representative solid wheel: tyre (rim), a straight web
offset from the contact, and a hub, all scaled with the rolling radius. It is an idealisation of
the UIC 920 mm freight and 840 mm passenger wheels (EN 13262 / EN 13979-1 outlines), not a
drawing.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from scipy import sparse

FloatArray = NDArray[np.float64]

_GAUSS_X = np.array([-np.sqrt(0.6), 0.0, np.sqrt(0.6)])
_GAUSS_W = np.array([5.0, 8.0, 5.0]) / 9.0


@dataclass(frozen=True)
class WheelSection:
    """Rectangular blocks of a solid wheel's cross-section [m]; z = 0 at the flange-side (inner) face.

    Defaults: a 920 mm wheel (rolling radius 0.46 m), rim 135 mm wide (EN 13715 profile S1002) and
    65 mm deep, web 30 mm thick centred 50 mm from the inner face (the contact at the nominal
    rolling circle, 70 mm from that face, is 20 mm outboard of the web: the offset through which a
    vertical force drives the axial modes), hub of 0.10-0.15 m radius. Steel: E = 210 GPa,
    nu = 0.3, rho = 7850 kg/m3.
    """

    rolling_radius_m: float = 0.46
    rim_depth_m: float = 0.065
    rim_width_m: float = 0.135
    web_thickness_m: float = 0.030
    web_centre_m: float = 0.050
    hub_outer_radius_m: float = 0.15
    bore_radius_m: float = 0.10
    contact_offset_m: float = 0.070
    young_pa: float = 2.1e11
    poisson: float = 0.3
    density: float = 7850.0

    @classmethod
    def scaled(cls, diameter_m: float) -> WheelSection:
        """The default section with the rolling radius of a wheel of this diameter [m]: the web
        longer or shorter, the rim, web thickness, hub and axle seat kept."""
        s = diameter_m / 2.0 / cls.rolling_radius_m
        d = cls()
        return cls(rolling_radius_m=d.rolling_radius_m * s, hub_outer_radius_m=d.hub_outer_radius_m,
                   bore_radius_m=d.bore_radius_m)

    def blocks(self) -> tuple[tuple[float, float, float, float], ...]:
        """Hub, web and rim as rectangles (r0, r1, z0, z1) [m]."""
        rim_in = self.rolling_radius_m - self.rim_depth_m
        w0, w1 = self.web_centre_m - self.web_thickness_m / 2, self.web_centre_m + self.web_thickness_m / 2
        return ((self.bore_radius_m, self.hub_outer_radius_m, 0.0, self.rim_width_m),
                (self.hub_outer_radius_m, rim_in, w0, w1),
                (rim_in, self.rolling_radius_m, 0.0, self.rim_width_m))


@dataclass(frozen=True)
class WheelModes:
    """Flexible modes of one wheel (arrays over modes).

    frequency_hz: natural frequency [Hz]; nodal_diameters: n [-]; contact_radial: radial (vertical
    at the contact) displacement of the unit-generalised-mass mode at the contact [kg^-1/2];
    axial_surface, radial_surface: integrals over the wheel's exterior of the squared axial
    displacement on faces normal to the axle and of the squared radial displacement on faces
    normal to the radius, theta included [m2/kg]; rolling_radius_m: outer radius [m].
    """

    frequency_hz: FloatArray
    nodal_diameters: NDArray[np.int64]
    contact_radial: FloatArray
    axial_surface: FloatArray
    radial_surface: FloatArray
    rolling_radius_m: float

    def arrays(self) -> dict[str, FloatArray]:
        """The per-mode arrays by name (MODE_ARRAYS)."""
        return {k: getattr(self, k) for k in MODE_ARRAYS}

    @property
    def contact_modal_mass_kg(self) -> FloatArray:
        """Modal mass seen by a vertical force at the contact, 1 / phi_c^2 [kg]."""
        return 1.0 / self.contact_radial**2


def _lines(edges: FloatArray, size_m: float) -> FloatArray:
    """Grid lines through the edges, each interval cut into elements of at most size_m, with midside lines."""
    pts = [np.linspace(a, b, 2 * max(1, int(np.ceil((b - a) / size_m - 1e-9))) + 1)[:-1]
           for a, b in pairwise(edges)]
    return np.concatenate([*pts, edges[-1:]])


def _mesh(blocks: tuple[tuple[float, float, float, float], ...], size_m: float
          ) -> tuple[FloatArray, FloatArray, NDArray[np.bool_]]:
    """Node lines in r and z (with midside lines) through the blocks' edges (r0, r1, z0, z1), and
    which grid cells are solid."""
    b = np.asarray(blocks, float)
    r = _lines(np.unique(b[:, :2]), size_m)
    z = _lines(np.unique(b[:, 2:]), size_m)
    rc, zc = (r[:-2:2] + r[2::2]) / 2, (z[:-2:2] + z[2::2]) / 2
    inside = ((rc[:, None, None] > b[:, 0]) & (rc[:, None, None] < b[:, 1])
              & (zc[None, :, None] > b[:, 2]) & (zc[None, :, None] < b[:, 3]))
    return r, z, inside.any(axis=-1)


def _shape_1d(x: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Quadratic Lagrange functions on [-1, 1] and their derivatives at x: (3, len(x)) each."""
    return (np.array([x * (x - 1) / 2, 1 - x**2, x * (x + 1) / 2]),
            np.array([x - 0.5, -2 * x, x + 0.5]))


def _elasticity(young_pa: float, poisson: float) -> FloatArray:
    """Isotropic stiffness for (e_r, e_theta, e_z, g_rz, g_rtheta, g_thetaz) [Pa]."""
    lam = young_pa * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = young_pa / (2 * (1 + poisson))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[np.arange(3), np.arange(3)] += 2 * mu
    d[np.arange(3, 6), np.arange(3, 6)] = mu
    return d


def _assemble(material: tuple[float, float, float], n: int, r: FloatArray, z: FloatArray,
              solid: NDArray[np.bool_]) -> tuple[sparse.csr_matrix, sparse.csr_matrix]:
    """Stiffness and mass of harmonic n over the whole wheel (theta integrated), 3 DOF per grid node."""
    from scipy import sparse  # here: only a table build solves modes (0.09 s of every node's start-up)

    nz = len(z)
    young, poisson, density = material
    d = _elasticity(young, poisson)
    n1, d1 = _shape_1d(_GAUSS_X)
    theta = np.pi if n else 2.0 * np.pi
    ci, cj = np.nonzero(solid)
    hr, hz = (r[2 * ci + 2] - r[2 * ci]) / 2, (z[2 * cj + 2] - z[2 * cj]) / 2           # (E,)
    rr = (r[2 * ci] + r[2 * ci + 2])[:, None, None] / 2 + hr[:, None, None] * _GAUSS_X[:, None]   # (E, 3, 1)
    # Shape functions at the 3 x 3 Gauss points (a along r, b along z) over the 9 nodes (p along r, q along z).
    nn = np.einsum("pa,qb->abpq", n1, n1).reshape(9, 9)
    dr = np.einsum("pa,qb->abpq", d1, n1).reshape(9, 9)
    dz = np.einsum("pa,qb->abpq", n1, d1).reshape(9, 9)
    rg = np.broadcast_to(rr, (len(ci), 3, 3)).reshape(len(ci), 9, 1)                   # (E, G, 1)
    nr, nzz, nor = dr / hr[:, None, None], dz / hz[:, None, None], nn / rg
    bm = np.zeros((len(ci), 9, 6, 27))
    bm[:, :, 0, 0::3] = nr
    bm[:, :, 1, 0::3], bm[:, :, 1, 1::3] = nor, n * nor
    bm[:, :, 2, 2::3] = nzz
    bm[:, :, 3, 0::3], bm[:, :, 3, 2::3] = nzz, nr
    bm[:, :, 4, 0::3], bm[:, :, 4, 1::3] = -n * nor, nr - nor
    bm[:, :, 5, 1::3], bm[:, :, 5, 2::3] = nzz, -n * nor
    w = (np.outer(_GAUSS_W, _GAUSS_W).ravel()[None, :] * (hr * hz)[:, None] * rg[..., 0] * theta)   # (E, G)
    ke = np.einsum("eg,egji,jk,egkl->eil", w, bm, d, bm, optimize=True)
    nmat = np.zeros((9, 3, 27))
    for c in range(3):
        nmat[:, c, c::3] = nn
    me = density * np.einsum("eg,gci,gcj->eij", w, nmat, nmat, optimize=True)
    nodes = ((2 * ci[:, None, None] + np.arange(3)[None, :, None]) * nz
             + 2 * cj[:, None, None] + np.arange(3)[None, None, :]).reshape(len(ci), 9)
    dofs = (3 * nodes[:, :, None] + np.arange(3)).reshape(len(ci), 27)
    rows = np.repeat(dofs, 27, axis=1).ravel()
    cols = np.tile(dofs, (1, 27)).ravel()
    kv, mv = ke.ravel(), me.ravel()
    size = 3 * len(r) * nz
    k = sparse.coo_matrix((kv, (rows, cols)), (size, size)).tocsr()
    m = sparse.coo_matrix((mv, (rows, cols)), (size, size)).tocsr()
    return k, m


def _exterior_integrals(n: int, r: FloatArray, z: FloatArray, solid: NDArray[np.bool_], shapes: FloatArray
                        ) -> tuple[FloatArray, FloatArray]:
    """Integrals over the exterior faces of U_z^2 (faces normal to z) and U_r^2 (faces normal to r),
    theta included, per mode: shapes (dofs, modes) on the grid."""
    nz = len(z)
    theta = np.pi if n else 2.0 * np.pi
    pad = np.pad(solid, 1)
    n1, _ = _shape_1d(_GAUSS_X)
    axial = np.zeros(shapes.shape[1])
    radial = np.zeros(shapes.shape[1])
    for i, j in zip(*np.nonzero(solid), strict=True):
        for side in (0, 1):
            if not pad[i + 1, j + 2 * side]:            # face z = z[2j] (side 0) or z[2j+2] exposed
                nodes = (2 * i + np.arange(3)) * nz + 2 * j + 2 * side
                u = n1.T @ shapes[3 * nodes + 2]            # (gauss, modes)
                rr = (r[2 * i] + r[2 * i + 2]) / 2 + (r[2 * i + 2] - r[2 * i]) / 2 * _GAUSS_X
                axial += theta * (r[2 * i + 2] - r[2 * i]) / 2 * ((_GAUSS_W * rr) @ u**2)
            if not pad[i + 2 * side, j + 1]:            # face r = r[2i] (side 0) or r[2i+2] exposed
                ri = 2 * i + 2 * side
                nodes = ri * nz + 2 * j + np.arange(3)
                u = n1.T @ shapes[3 * nodes]
                radial += theta * r[ri] * (z[2 * j + 2] - z[2 * j]) / 2 * (_GAUSS_W @ u**2)
    return axial, radial


def harmonic_modes(blocks: tuple[tuple[float, float, float, float], ...], material: tuple[float, float, float],
                   n: int, max_hz: float, contact: tuple[float, float], clamp_radius_m: float | None = None,
                   size_m: float = 0.02) -> WheelModes:
    """Modes of one Fourier harmonic of a solid of revolution by axisymmetric finite elements.

    Parameters
    ----------
    blocks : tuple of (float, float, float, float)
        Rectangular blocks (r0, r1, z0, z1) of the cross-section [m].
    material : (float, float, float)
        E [Pa], nu [-], rho [kg/m3].
    n : int
        Nodal diameters [-].
    max_hz : float
        Highest frequency kept [Hz].
    contact : (float, float)
        (r, z) where the radial displacement is read [m].
    clamp_radius_m : float, optional
        Radius whose nodes are fixed [m] (None: a free body, whose rigid-body modes come out near 0 Hz).
    size_m : float
        Largest element [m].

    Returns
    -------
    WheelModes
        Frequencies [Hz], nodal diameters [-], contact displacements [kg^-1/2] and surface
        integrals [m2/kg] of the modes.

    References
    ----------
    .. [1] D. J. Thompson, "Wheel-rail noise generation, part II: wheel vibration", *Journal of
       Sound and Vibration* 161 (1993) 401-419.
    .. [2] O. C. Zienkiewicz and R. L. Taylor, *The Finite Element Method*, vol. 1, 5th ed.,
       Butterworth-Heinemann, Oxford, 2000, section 9.6.
    """
    r, z, solid = _mesh(blocks, size_m)
    from scipy.sparse.linalg import eigsh

    k, m = _assemble(material, n, r, z, solid)
    nz = len(z)
    used = np.zeros(len(r) * nz, bool)
    for i, j in zip(*np.nonzero(solid), strict=True):
        used[((2 * i + np.arange(3))[:, None] * nz + (2 * j + np.arange(3))[None, :]).ravel()] = True
    if clamp_radius_m is not None:
        used &= ~np.isclose(np.repeat(r, nz), clamp_radius_m)
    keep = np.repeat(used, 3)
    if n == 0:
        keep &= np.tile(np.array([True, False, True]), len(used))   # no U_theta: torsion is another family
    idx = np.nonzero(keep)[0]
    kk, mm = k[idx][:, idx].tocsc(), m[idx][:, idx].tocsc()
    # Shift below zero so that a free body's rigid-body modes do not make the shifted matrix singular;
    # ask for more modes until one lies above max_hz (or all are found).
    # A fixed start vector: ARPACK's own draws from a generator it keeps between calls, so the modes'
    # last bits would depend on what the process solved before.
    start = np.random.default_rng(0).standard_normal(len(idx))
    count = 14
    while True:
        count = min(count, len(idx) - 2)
        lam, vec = eigsh(kk, k=count, M=mm, sigma=-(2 * np.pi * 5.0) ** 2, which="LM", v0=start)
        if np.sqrt(max(lam.max(), 0.0)) / (2 * np.pi) > max_hz or count == len(idx) - 2:
            break
        count *= 2
    order = np.argsort(lam)
    lam, vec = np.maximum(lam[order], 0.0), vec[:, order]
    sel = np.sqrt(lam) / (2 * np.pi) <= max_hz
    lam, vec = lam[sel], vec[:, sel]
    vec = vec / np.sqrt(np.einsum("im,im->m", vec, mm @ vec))          # unit generalised mass
    shapes = np.zeros((3 * len(r) * nz, vec.shape[1]))
    shapes[idx] = vec
    node = np.argmin(np.abs(r - contact[0])) * nz + np.argmin(np.abs(z - contact[1]))
    axial, radial = _exterior_integrals(n, r, z, solid, shapes)
    return WheelModes(np.sqrt(lam) / (2 * np.pi), np.full(len(lam), n, np.int64), shapes[3 * node], axial, radial,
                      float(np.max(np.asarray(blocks)[:, 1])))


def wheel_modes(section: WheelSection, max_hz: float = 12000.0, size_m: float = 0.012) -> WheelModes:
    """All flexible modes of the clamped-bore wheel below max_hz, harmonic by harmonic.

    Harmonics n = 0, 1, ... up to the first whose lowest mode lies above max_hz.

    Parameters
    ----------
    section : WheelSection
        The wheel's cross-section [m] and material.
    max_hz : float
        Highest frequency kept [Hz].
    size_m : float
        Largest element [m].

    Returns
    -------
    WheelModes
        As :func:`harmonic_modes`, over every harmonic.

    References
    ----------
    .. [1] D. J. Thompson, "Wheel-rail noise generation, part II: wheel vibration", *Journal of
       Sound and Vibration* 161 (1993) 401-419.
    """
    material = (section.young_pa, section.poisson, section.density)
    contact = (section.rolling_radius_m, section.contact_offset_m)
    parts: list[WheelModes] = []
    for n in range(64):
        got = harmonic_modes(section.blocks(), material, n, max_hz, contact, section.bore_radius_m, size_m)
        if not len(got.frequency_hz) and n >= 2:
            break
        parts.append(got)
    return WheelModes(*(np.concatenate([getattr(p, name) for p in parts]) for name in MODE_ARRAYS),
                      section.rolling_radius_m)


MODE_ARRAYS = ("frequency_hz", "nodal_diameters", "contact_radial", "axial_surface", "radial_surface")
