"""Speed plans per vehicle class: the shares of each class's trains in speed bands that minimise the
peak corrugation growth, under linear limits on what else the speeds change.

The growth per axle pass of a band component is linear in the shares (the UQ paper's eq. 2 over
a speed distribution), and so are a pass-weighted mean noise level in dB(A) and the share of
passes at a squeal risk, each tabulated per class and speed band. Minimising the largest growth
over the components is then the linear programme

    min t   s.t.   sum_c w_c sum_s G[c, r, s] p[c, s] <= t          (every component r)
                   sum_s p[c, s] = 1,  sum_s v[c, s] p[c, s] = m_c   (every class c: same mean speed)
                   sum_c sum_s A_k[c, s] p[c, s] <= b_k              (every further limit k)
                   0 <= p[c, s] <= cap_c,  p[c, s] = 0 outside the class's allowed bands

solved exactly (HiGHS, scipy.optimize.linprog). w_c is class c's share of the axle passes. A
vertex solution uses few bands per class, which is what an operator can publish.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


class SpeedPlan(NamedTuple):
    """share: (C, S) the shares of each class's passes per band [-] (rows sum to 1); peak_growth:
    the largest component growth [1/axle pass]; growth: per component (R,) [1/axle pass]."""

    share: FloatArray
    peak_growth: float
    growth: FloatArray


def plan_growth(growth: ArrayLike, axle_weight: ArrayLike, share: ArrayLike) -> FloatArray:
    """Growth per axle pass of every component (R,) for shares p (C, S): sum_c w_c G[c] @ p[c]."""
    return np.einsum("c,crs,cs->r", np.asarray(axle_weight, float), np.asarray(growth, float),
                     np.asarray(share, float))


def optimise_speed_plan(growth: ArrayLike, axle_weight: ArrayLike, speeds: ArrayLike, allowed: ArrayLike,
                        mean_speed: ArrayLike, cap: ArrayLike,
                        limits: Sequence[tuple[ArrayLike, float]] = ()) -> SpeedPlan:
    """The plan of least peak growth (module docstring).

    growth G (C, R, S) [1/axle pass]; axle_weight w (C,) [-]; speeds: band centres v (C, S) [m/s];
    allowed (C, S) bool; mean_speed m (C,) [m/s]; cap (C,) [-]; limits: (A (C, S), b) pairs for
    sum A p <= b. ValueError when no plan meets the constraints.
    """
    g = np.asarray(growth, float)
    w = np.asarray(axle_weight, float)
    v = np.asarray(speeds, float)
    ok = np.asarray(allowed, bool)
    m = np.asarray(mean_speed, float)
    caps = np.asarray(cap, float)
    nc, nr, ns = g.shape
    cols = np.flatnonzero(ok.ravel())           # the free shares, class-major
    cls_of = cols // ns
    band_of = cols % ns
    n = len(cols)
    scale = float(np.max(np.abs(g))) or 1.0     # g is of order 1e-6: scale it for the solver's tolerances
    # Growth rows: (w_c G[c, r, s] / scale) p - t <= 0.
    a_growth = (w[cls_of][None, :] * g[cls_of, :, band_of].T) / scale
    a_ub = [np.c_[a_growth, -np.ones(nr)]]
    b_ub = [np.zeros(nr)]
    for coef, bound in limits:
        a = np.asarray(coef, float)
        a_ub.append(np.r_[a[cls_of, band_of], 0.0][None, :])
        b_ub.append(np.array([bound]))
    a_eq = np.zeros((2 * nc, n + 1))
    a_eq[cls_of, np.arange(n)] = 1.0
    a_eq[nc + cls_of, np.arange(n)] = v[cls_of, band_of] / np.where(m[cls_of] > 0, m[cls_of], 1.0)
    b_eq = np.r_[np.ones(nc), np.ones(nc)]
    from scipy.optimize import linprog  # lazy: scipy.optimize costs 0.3 s to import

    res = linprog(np.r_[np.zeros(n), 1.0], A_ub=np.vstack(a_ub), b_ub=np.concatenate(b_ub), A_eq=a_eq, b_eq=b_eq,
                  bounds=[(0.0, caps[c]) for c in cls_of] + [(None, None)], method="highs")
    if res.status != 0:
        raise ValueError(f"speed plan: {res.message}")
    share = np.zeros((nc, ns))
    share.ravel()[cols] = np.clip(res.x[:n], 0.0, None)
    share /= share.sum(axis=1, keepdims=True)
    per_row = plan_growth(g, w, share)
    return SpeedPlan(share, float(per_row.max()), per_row)
