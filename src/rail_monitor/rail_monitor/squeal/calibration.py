"""The squeal model calibrated from the site: each friction state's creep curve re-fitted from
measured squeal, as a posterior on a grid (no rclpy).

The creep curve of a friction state is its peak k1 and its falling slope k2 (UQ paper, eq. 2 and
section 3.3). Squeal onset and amplitude depend on them through the saturation creepage
zeta_c = W / k3, which scales with k1 (contact.k3_convention reduced_kalker), through the
effective damping c + k2 k3 / V0 (eq. 5), negative when the falling slope outweighs the modal
damping, and through the limit cycle (eq. 7). Parametrised as

    k1 = k1_0 exp(a),    k2 = k1 s,

with k1_0 the configured peak, a the log-ratio of the peak (prior normal, sd ``prior_sd_peak``)
and s the relative slope k2 / k1 (prior normal about the configured k2_0 / k1_0, sd
``prior_sd_slope``: additive, so a friction modifier's rising curve may be found falling).

Each measured pass of a state updates its log-posterior on a GRID x GRID grid over +-3 prior sd:

- occurrence: the pass squeals in the model when it is unstable and its level reaches the dB(A)
  threshold of ``min_risk`` (the alerts' rule, the squeal.risk_* limits). The station hears that
  threshold with an uncertainty: P(flag) = e + (1 - 2 e) Phi((L - L_risk) / ``occurrence_sd_db``),
  L the model's level (-inf where stable), e = ``flag_error`` the station's own misclassification.
  The probit makes the likelihood continuous in the curve through the level (the limit cycle's
  amplitude grows from 0 at onset), so that a grid step does not decide a pass near threshold;
- level, where measured on a pass flagged squealing: normal about the model's tone level at the
  station's distance (point-source spreading from the squeal model's receiver), sd ``level_sd_db``,
  where the model squeals; a flag error's level is uniform over LEVEL_SPAN_DB.

The posterior's P10/P50/P90 of k1 and k2 are weighted quantiles over the grid's cells. Occurrence
alone identifies the onset (zeta_c, so k1) from the angles of attack at which passes start to
squeal, and the relative slope only as far as the traffic's speeds and classes straddle the
damping threshold of eq. 5, -s k1 k3 > c V0 (with k3 proportional to 1 / k1, a condition on s
alone): where every pass past onset is unstable, s is bounded on one side only. Levels identify
the limit cycle's amplitude, and so both.

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and acoustic
   phenomena", seminar paper, sections 2.3 and 3 (eqs. 2-7): the creep curve, the instability and
   the limit cycle the fit re-evaluates (docs/models.md, "Wheel squeal").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.special import ndtr

from rail_monitor.core.contact import contact_state
from rail_monitor.core.friction import FRICTION_NAMES
from rail_monitor.core.passes import PassTable
from rail_monitor.core.site import Site
from rail_monitor.models import squeal
from rail_monitor.models.squeal_balance import COARSE_BALANCE
from rail_monitor.squeal.config import RISK_HIGH, RISK_MEDIUM, SquealConfig
from rail_monitor.squeal.predict import WheelMode, level_and_risk, wheel_mode
from rail_monitor.squeal.share_check import ShareCheck, share_quantiles

GRID = 21             # points per parameter
SPAN_SD = 3.0         # the grid's half-width [prior sd]
LEVEL_SPAN_DB = 60.0  # the span of a flag error's level [dB]
CHUNK = 512           # passes evaluated on the grid at a time (memory: CHUNK x GRID^2 doubles per array)
MIN_CELLS = 6         # a zoom's tempered posterior spans at least this many cells each way


@dataclass(frozen=True)
class FitConfig:
    """How the squeal model is re-fitted (units in the module docstring)."""

    prior_sd_peak: float = 0.4      # sd of log(k1 / k1_0) [-]
    prior_sd_slope: float = 0.05    # sd of k2 / k1 [-]
    flag_error: float = 0.05        # a station's flag disagreeing with the truth [-]
    occurrence_sd_db: float = 2.0   # the level threshold of hearing squeal, its uncertainty [dB]
    level_sd_db: float = 3.0        # a measured tone level about the model's [dB]
    min_risk: int = 2               # the risk that counts as squealing (RISK_MEDIUM)


def fit_config(cfg: SquealConfig, min_risk: int) -> FitConfig:
    """The fit of a site's squeal parameters (its ``squeal.fit_prior_*``), squealing counted from
    min_risk (the alerts' ``squeal_min_risk``, as a RISK_* value)."""
    return FitConfig(prior_sd_peak=cfg.fit_prior_sd_peak, prior_sd_slope=cfg.fit_prior_sd_slope,
                     flag_error=cfg.fit_flag_error, min_risk=min_risk)


@dataclass(frozen=True)
class CurveQuantiles:
    """A friction state's fitted creep curve: quantiles (P10, P50, P90) of k1 and of k2 [-], and
    the passes seen and flagged squealing."""

    k1: tuple[float, ...]
    k2: tuple[float, ...]
    passes: int
    squealed: int


def _span(centre: float, half: float) -> np.ndarray:
    return centre + half * np.linspace(-1.0, 1.0, GRID)


class SquealFit:
    """Per friction state, the log-posterior of (a, s) on a grid that follows the posterior's mass
    (:meth:`refine`); the prior is the site's curves. The measured passes are kept, so that a finer
    grid is evaluated on every one of them."""

    def __init__(self, site: Site, squeal_cfg: SquealConfig, cfg: FitConfig = FitConfig()) -> None:
        self.site, self.squeal_cfg, self.cfg = site, squeal_cfg, cfg
        self.grids: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # state -> (a, s) grid axes
        self.log_post: dict[int, np.ndarray] = {}
        self.kept: dict[int, list[tuple[PassTable, np.ndarray, np.ndarray]]] = {}
        self.seen: dict[int, list[int]] = {}  # state -> [passes, squealed]
        for code in FRICTION_NAMES:
            axes = (_span(0.0, SPAN_SD * cfg.prior_sd_peak), _span(self._slope0(code), SPAN_SD * cfg.prior_sd_slope))
            self._regrid(code, axes)
            self.kept[code], self.seen[code] = [], [0, 0]

    def _slope0(self, code: int) -> float:
        k1, k2 = (float(x[0]) for x in self.site.contact.creep(np.array([code])))
        return k2 / k1

    def _prior(self, code: int) -> np.ndarray:
        """The log-prior on the state's grid (GRID, GRID)."""
        a, s = self.grids[code]
        return (-0.5 * (a[:, None] / self.cfg.prior_sd_peak) ** 2
                - 0.5 * ((s[None, :] - self._slope0(code)) / self.cfg.prior_sd_slope) ** 2)

    def _regrid(self, code: int, axes: tuple[np.ndarray, np.ndarray]) -> None:
        """The prior on a new grid (the kept passes to be added by the caller)."""
        self.grids[code] = axes
        self.log_post[code] = self._prior(code)

    def curves(self, code: int) -> tuple[np.ndarray, np.ndarray]:
        """k1 and k2 on the grid (GRID, GRID) of a state."""
        a, s = self.grids[code]
        k1 = float(self.site.contact.creep(np.array([code]))[0][0]) * np.exp(a)[:, None] * np.ones((1, GRID))
        return k1, k1 * s[None, :]

    def squeals(self, passes: PassTable, code: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Whether each pass squeals (risk >= min_risk), its level [dB(A)] (-inf: stable) and its
        tone level [dB re 20 uPa], both at the squeal model's receiver, at every grid point of state
        code: arrays (N, GRID, GRID). The passes are valid, class defaults filled, and taken as run
        in that state."""
        cs = contact_state(self.site, passes, np.full(len(passes), code))
        mode = wheel_mode(self.site, passes.vehicle_class)
        k1, k2 = self.curves(code)
        kalker = None if cs.kalker_n is None else cs.kalker_n[:, None, None]
        c = self.site.contact
        k3 = (np.full((len(passes), 1, 1), c.k3_n) if kalker is None
              else squeal.lateral_creep_stiffness(kalker, k1[None], c.k3_convention, c.creep_reduction_factor))
        col = [x[:, None, None] for x in (passes.speed_mps, cs.crabbing_mps, cs.load_n, mode.damping_nspm)]
        shape = (len(passes), GRID, GRID)
        lc = squeal.limit_cycle_amplitude(*(np.broadcast_to(x, shape) for x in (*col, k1[None], k2[None], k3)),
                                          resolution=COARSE_BALANCE)
        grid_mode = WheelMode(*(np.broadcast_to(f[:, None, None], shape) for f in mode))
        lev, risk = level_and_risk(self.squeal_cfg, grid_mode, lc.amplitude, lc.unstable)
        return risk >= self.cfg.min_risk, np.where(lc.unstable, lev.level_dba, -np.inf), lev.level_db

    def _threshold_dba(self) -> float:
        """The level [dB(A)] from which a pass counts as squealing (-inf: any unstable pass)."""
        c = self.squeal_cfg
        return {RISK_MEDIUM: c.risk_medium_dba, RISK_HIGH: c.risk_high_dba}.get(self.cfg.min_risk, -np.inf)

    def _log_likelihood(self, code: int, passes: PassTable, squealed: np.ndarray, level: np.ndarray,
                        moments: np.ndarray | None = None) -> np.ndarray:
        """The passes' log-likelihood on the state's grid (GRID, GRID); level at the model's receiver.
        moments (2, GRID, GRID), if given, gains the sums over the passes of the chance p of a flag
        and of p (1 - p) (squeal.share_check)."""
        eps, sd = self.cfg.flag_error, self.cfg.level_sd_db
        out = np.zeros((GRID, GRID))
        for lo in range(0, len(passes), CHUNK):
            part = slice(lo, lo + CHUNK)
            model, model_dba, model_db = self.squeals(passes.take(part), code)
            y = squealed[part][:, None, None]
            with np.errstate(invalid="ignore"):
                heard = ndtr((model_dba - self._threshold_dba()) / self.cfg.occurrence_sd_db)
            heard = np.where(np.isfinite(model_dba), np.nan_to_num(heard, nan=1.0), 0.0)
            p = eps + (1.0 - 2.0 * eps) * heard
            if moments is not None:
                moments += (p.sum(axis=0), (p * (1.0 - p)).sum(axis=0))
            ll = np.where(y, np.log(p), np.log1p(-p))
            measured = y & np.isfinite(level[part])[:, None, None]
            with np.errstate(invalid="ignore"):
                z = (level[part][:, None, None] - model_db) / sd
                ll += np.where(measured & model, -0.5 * z * z - np.log(sd * np.sqrt(2 * np.pi)),
                               np.where(measured, -np.log(LEVEL_SPAN_DB), 0.0))
            out += ll.sum(axis=0)
        return out

    def observe(self, passes: PassTable, squealed: np.ndarray, level_db: np.ndarray,
                distance_m: np.ndarray) -> dict[int, ShareCheck]:
        """Take measured passes (valid, class defaults filled): whether each was flagged squealing,
        its tone level [dB re 20 uPa] (NaN: not measured) at the microphone's distance [m]. Returns,
        per state with passes, their share flagged and the share the posterior before them predicted."""
        squealed = np.asarray(squealed, bool)
        # The tone's level brought to the squeal model's receiver (a point source's spreading).
        level = np.asarray(level_db, float) + 20.0 * np.log10(np.asarray(distance_m, float)
                                                               / self.squeal_cfg.receiver_distance_m)
        checks = {}
        for code in self.log_post:
            rows = np.flatnonzero(passes.friction_state == code)
            if not len(rows):
                continue
            part = (passes.take(rows), squealed[rows], level[rows])
            self.kept[code].append(part)
            moments, before = np.zeros((2, GRID, GRID)), self.weights(code)
            self.log_post[code] += self._log_likelihood(code, *part, moments=moments)
            flagged = int(squealed[rows].sum())
            self.seen[code][0] += len(rows)
            self.seen[code][1] += flagged
            checks[code] = ShareCheck(len(rows), flagged, share_quantiles(before, *moments, len(rows)))
        return checks

    def _merged(self, code: int) -> tuple[PassTable, np.ndarray, np.ndarray] | None:
        """The state's kept passes as one part (None: none)."""
        parts = self.kept[code]
        if len(parts) > 1:
            parts[:] = [(PassTable.concat([p[0] for p in parts]), *(np.concatenate([p[i] for p in parts])
                                                                     for i in (1, 2)))]
        return parts[0] if parts else None

    def keep_newest(self, code: int, n: int) -> None:
        """Keep the state's newest n measured passes: the older ones' likelihood is taken out of the
        posterior, which is then that of the newest n (a site's friction changes with the seasons)."""
        kept = self._merged(code)
        if kept is None or len(kept[0]) <= n:
            return
        drop = len(kept[0]) - n
        old = (kept[0].take(slice(0, drop)), kept[1][:drop], kept[2][:drop])
        self.log_post[code] -= self._log_likelihood(code, *old)
        self.kept[code] = [(kept[0].take(slice(drop, None)), kept[1][drop:], kept[2][drop:])]
        self.seen[code] = [self.seen[code][0] - drop, self.seen[code][1] - int(old[1].sum())]

    def to_arrays(self, prefix: str) -> dict[str, np.ndarray]:
        """Every state's grid, log-posterior and kept passes, for a checkpoint (keys under prefix)."""
        out: dict[str, np.ndarray] = {}
        for code in FRICTION_NAMES:
            kept = self._merged(code) or (PassTable.empty(), np.zeros(0, bool), np.zeros(0))
            p = f"{prefix}{code}_"
            out.update({f"{p}a": self.grids[code][0], f"{p}s": self.grids[code][1], f"{p}log_post": self.log_post[code],
                        f"{p}seen": np.array(self.seen[code], np.int64), f"{p}squealed": kept[1],
                        f"{p}level": kept[2],
                        **{f"{p}pass_{c}": getattr(kept[0], c) for c in PassTable.columns()}})
        return out

    def restore(self, arrays: dict[str, np.ndarray], prefix: str) -> None:
        """Resume from to_arrays's records (ValueError, the fit untouched, if they are not usable)."""
        grids, log_post, kept, seen = {}, {}, {}, {}
        for code in FRICTION_NAMES:
            p = f"{prefix}{code}_"
            a, s, lp = (np.asarray(arrays[f"{p}{k}"], float) for k in ("a", "s", "log_post"))
            table = PassTable(**{c: np.asarray(arrays[f"{p}pass_{c}"]).astype(PassTable.DTYPES[c])
                                 for c in PassTable.columns()})
            squealed, level = np.asarray(arrays[f"{p}squealed"]).astype(bool), np.asarray(arrays[f"{p}level"], float)
            counts = np.asarray(arrays[f"{p}seen"]).astype(np.int64, casting="same_kind")
            if a.shape != (GRID,) or s.shape != (GRID,) or lp.shape != (GRID, GRID) or not np.all(np.isfinite(lp)) \
                    or squealed.shape != (len(table),) or level.shape != (len(table),) or counts.shape != (2,) \
                    or counts[0] != len(table) or not 0 <= counts[1] <= counts[0]:
                raise ValueError(f"squeal fit records of friction state {code} have the wrong shape or counts")
            grids[code], log_post[code], seen[code] = (a, s), lp, counts.tolist()
            kept[code] = [(table, squealed, level)] if len(table) else []
        self.grids, self.log_post, self.kept, self.seen = grids, log_post, kept, seen

    def refine(self, code: int, rounds: int = 8) -> None:
        """Zoom the state's grid onto its posterior and evaluate every kept pass on it.

        The likelihood of thousands of passes is far narrower than a grid over the prior, and a
        coarse grid's cells may all miss the true curve's narrow peak. So each round tempers the
        likelihood (divides it by T, the least power of two that spreads the posterior's
        P0.1-P99.9 over at least MIN_CELLS cells both ways), takes that span (a cell wider each
        side, within the prior's +-SPAN_SD) as the next grid, and stops when the untempered
        posterior already spans a quarter of the grid both ways."""
        prior_a = SPAN_SD * self.cfg.prior_sd_peak
        s0, prior_s = self._slope0(code), SPAN_SD * self.cfg.prior_sd_slope
        for _ in range(rounds):
            a, s = self.grids[code]
            prior = self._prior(code)
            like = self.log_post[code] - prior
            da, ds = a[1] - a[0], s[1] - s[0]
            for t in 2.0 ** np.arange(0, 31):
                (lo_a, hi_a), (lo_s, hi_s) = _mass_span(a, s, prior + like / t)
                if (hi_a - lo_a) >= MIN_CELLS * da and (hi_s - lo_s) >= MIN_CELLS * ds:
                    break
            if t == 1.0 and hi_a - lo_a >= 0.25 * (a[-1] - a[0]) and hi_s - lo_s >= 0.25 * (s[-1] - s[0]):
                return
            axes = (np.linspace(max(lo_a - da, -prior_a), min(hi_a + da, prior_a), GRID),
                    np.linspace(max(lo_s - ds, s0 - prior_s), min(hi_s + ds, s0 + prior_s), GRID))
            self._regrid(code, axes)
            for part in self.kept[code]:
                self.log_post[code] += self._log_likelihood(code, *part)

    def weights(self, code: int) -> np.ndarray:
        """The posterior's weights on the grid of a state (GRID, GRID), summing to 1."""
        lp = self.log_post[code]
        w = np.exp(lp - lp.max())
        return w / w.sum()

    def quantiles(self, code: int, q: tuple[float, ...] = (0.1, 0.5, 0.9)) -> CurveQuantiles:
        """The state's quantiles q (default P10, P50, P90) of k1 and of k2."""
        w = self.weights(code).ravel()
        k1, k2 = (x.ravel() for x in self.curves(code))
        return CurveQuantiles(tuple(_weighted_quantiles(k1, w, q)), tuple(_weighted_quantiles(k2, w, q)),
                              *self.seen[code])

    def predicted_share(self, passes: PassTable, code: int) -> float:
        """The share of passes that squeal in state code under the posterior (its predictive mean)."""
        if not len(passes):
            return float("nan")
        w = self.weights(code)
        total = 0.0
        for lo in range(0, len(passes), CHUNK):
            model, _, _ = self.squeals(passes.take(slice(lo, lo + CHUNK)), code)
            total += float((model.sum(axis=0) * w).sum())
        return total / len(passes)


def _mass_span(a: np.ndarray, s: np.ndarray, log_post: np.ndarray) -> tuple[tuple[float, float], ...]:
    """P0.1 and P99.9 of each axis's marginal under a log-posterior on the grid."""
    w = np.exp(log_post - log_post.max())
    w /= w.sum()
    return (tuple(_weighted_quantiles(a, w.sum(axis=1), (0.001, 0.999))),
            tuple(_weighted_quantiles(s, w.sum(axis=0), (0.001, 0.999))))


def _weighted_quantiles(x: np.ndarray, w: np.ndarray, q: tuple[float, ...]) -> np.ndarray:
    """Quantiles q of values x with weights w (summing to 1): the inverse of the mid-point CDF."""
    order = np.argsort(x, kind="stable")
    xs, cw = x[order], np.cumsum(w[order]) - 0.5 * w[order]
    return np.interp(q, cw, xs)
