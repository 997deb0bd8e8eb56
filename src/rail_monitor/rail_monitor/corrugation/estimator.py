"""The corrugation state of one site: roughness per wavelength band, advanced pass by pass.

Each band is tracked as components at wavelengths across it (:mod:`.growth`); a band's r.m.s.
is the energy sum of its components, so it tends to grow at the rate of its fastest one: that
rate is the band's g, and the peak g over bands is what the speed advice minimises.

A pass is identified by (stamp, train_id): a pass already counted, or older than the kept
history, is not counted (so a replay does not grow the state twice), and because ln Z is a sum,
passes give the same state one by one or in a batch. Live, replay and batch all call
:meth:`CorrugationEstimator.advance_history` with one pass or many.

Surveys and grinding (:mod:`.surveys`), what-if speed distributions and advice (:mod:`.advice`)
and checkpoints (:mod:`.checkpoint`) are functions of this state.
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.contact import contact_state
from rail_monitor.core.errors import ConfigError
from rail_monitor.core.passes import PassTable
from rail_monitor.core.site import Site
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.corrugation import forecast as fcst
from rail_monitor.corrugation.config import CorrugationConfig
from rail_monitor.corrugation.growth import GrowthTables
from rail_monitor.corrugation.history import KeptPasses, RowQueue, dropped
from rail_monitor.corrugation.records import Forecast, ForecastInterval, StateSnapshot, Trajectory
from rail_monitor.corrugation.season import DailyGrowth, modifier_share
from rail_monitor.models import calibration
from rail_monitor.models import corrugation_bands as cbands
from rail_monitor.models import corrugation_state as cstate
from rail_monitor.models.engine import corrugation_kernels


class CorrugationEstimator:
    """The corrugation state of one site and its forecast (no ROS)."""

    def __init__(self, site: Site, cfg: CorrugationConfig, tables: GrowthTables | None = None) -> None:
        self.site, self.cfg = site, cfg
        self.tables = tables or GrowthTables(site, cfg)
        self.tables.set_k_b(cfg.k_b)
        self.bands = self.tables.bands
        acceptance = cbands.band_limits(self.bands) * cfg.acceptance_factor
        if np.any(np.isnan(acceptance)):
            raise ConfigError("corrugation bands reach outside the 10-3000 mm of the Grassie et al. (1999) limits")
        self.threshold = acceptance * cfg.intervention_factor
        self.post_grinding = acceptance * cfg.post_grinding_fraction
        self.history_ns = int(cfg.history_days * NS_PER_DAY)
        self.points = cfg.points_per_band
        self.log_components = self.flat(self.post_grinding)
        self.grinding_amplitude = self.post_grinding.copy()             # r.m.s. after the last grinding
        self.pass_count = self.axle_pass_count = self.total_pass_count = 0
        self.last_grinding_ns = self.newest_ns = 0
        self.newest_train_id = ""                                      # train_id of the newest pass counted
        self.last_survey_ns = 0                                        # last survey or grinding applied
        self.survey_log_amplitude = np.full(len(self.bands), np.nan)   # last survey, NaN: band not measured
        # Log growth since the last survey or grinding per friction state (4, B, P), at the K_b in
        # use: what the next survey re-fits K_b against (rail_monitor.models.calibration).
        self.growth_by_state = np.zeros((4, *self.log_components.shape))
        self.calibration = calibration.prior(cfg.kb_prior_scale_sd, cfg.kb_prior_ratio_sd)
        self.survey_var = calibration.log_variance(cfg.survey_uncertainty_db)  # of ln Z, a surveyed band [-]
        self.post_grinding_var = np.full(len(self.bands), calibration.log_variance(cfg.post_grinding_uncertainty_db))
        # Covariance of each band's ln Z at the last survey or grinding (B, B), and with u (B, 4)
        self.level_cov, self.level_kb_cov = np.diag(self.post_grinding_var), np.zeros((len(self.bands), 4))
        self.kept = KeptPasses()
        self.season = DailyGrowth(self.log_components.shape)  # the last year day by day (forecast interval)
        self.engine = "numpy"  # of the state's array kernels (batch: numba; models.engine.corrugation_kernels)
        # Log growth summed in counting order: before each kept pass (K, B, P), and after the last
        # (B, P). A window's growth is a difference of two, so it is the same however the passes
        # were split into calls (live backlogs, batch chunks).
        self._growth_before = RowQueue(np.zeros((0, *self.log_components.shape)))
        self._growth_total = np.zeros_like(self.log_components)
        self._axles_before = RowQueue(np.zeros(0, np.int64))  # axles summed the same way (K,), and after
        self._axle_total = 0

    # -- passes ---------------------------------------------------------------------------------
    def advance(self, passes: PassTable) -> np.ndarray:
        """Count the passes not seen before; return the mask of those counted.

        ``passes`` must be valid for the site with class defaults filled. A pass is not counted
        when its (stamp, train_id) was counted already or is older than the kept history.
        """
        return self._advance(passes)[0]

    def _growth(self, class_idx: np.ndarray, friction: np.ndarray, regime: np.ndarray, speed: np.ndarray,
                axles: np.ndarray) -> np.ndarray:
        """Log growth of each component (N, B, P) over the axles of N passes."""
        return self.tables.at(class_idx, friction, regime, speed, axles, self.engine)

    def _advance(self, passes: PassTable) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]:
        """advance(), also returning ln Z after each counted pass (counted, B, P) and the log growth
        summed in counting order before each counted pass and after the last (counted + 1, B, P)."""
        counted = self._first_sight(passes)
        if not counted.any():
            return counted, (np.zeros((0, *self.log_components.shape)), self._growth_total[None].copy())
        new = passes.take(counted)
        cls = self.tables.class_index(new.vehicle_class)
        contact = contact_state(self.site, new)
        growth = self._growth(cls, new.friction_state, contact.regime, new.speed_mps, new.axle_count)
        kernels = corrugation_kernels(self.engine)
        friction = np.asarray(new.friction_state)
        steps, summed = kernels.history_sums(self.log_components, self._growth_total, self.growth_by_state, growth,
                                             friction)
        self.log_components = steps[-1].copy()
        self.season.add(new.stamp_ns, friction, growth, self.k_b, self.engine)
        self._growth_before.append(summed[:-1])
        self._growth_total = summed[-1].copy()
        axles_summed = self._axle_total + np.concatenate([[0], np.cumsum(new.axle_count)])
        self._axles_before.append(axles_summed[:-1])
        self._axle_total = int(axles_summed[-1])
        m = int(counted.sum())
        self.pass_count += m
        self.total_pass_count += m
        self.axle_pass_count += int(new.axle_count.sum())
        i_new = len(new) - 1 - int(np.argmax(new.stamp_ns[::-1]))  # the last of equal stamps, as one by one
        if int(new.stamp_ns[i_new]) >= self.newest_ns:
            self.newest_ns, self.newest_train_id = int(new.stamp_ns[i_new]), str(new.train_id[i_new])
        self.kept.extend(stamp_ns=new.stamp_ns, train_id=new.train_id, class_idx=cls, friction=new.friction_state,
                         regime=contact.regime.astype(np.int64), speed=new.speed_mps, axles=new.axle_count,
                         load=contact.load_n, creepage=contact.creepage)
        self._prune()
        return counted, (steps, summed)

    def _first_sight(self, passes: PassTable) -> np.ndarray:
        """Mark the passes to count: keys not seen (nor twice among them), not older than the kept
        history as it moves on pass by pass."""
        stamps = passes.stamp_ns
        newest = self.kept.newest_ns()
        # Strictly in time order and newer than every kept pass: none is seen, none repeated.
        if not len(stamps) or ((newest is None or stamps[0] > newest) and stamps[0] >= self.newest_ns - self.history_ns
                                and bool(np.all(np.diff(stamps) > 0))):
            return np.ones(len(stamps), bool)
        horizon = self.newest_ns - self.history_ns
        seen = set(self.kept.seen())
        counted = np.zeros(len(stamps), bool)
        for i, key in enumerate(zip(stamps.tolist(), passes.train_id.tolist(), strict=True)):
            if key in seen or key[0] < horizon:
                continue
            seen.add(key)
            counted[i] = True
            horizon = max(horizon, key[0] - self.history_ns)
        return counted

    def advance_history(self, passes: PassTable) -> Trajectory:
        """advance() over one pass or a history, returning the state and forecast after every
        counted pass, equal to what advancing one pass at a time gives.

        Vectorised when the passes are in time order and none is older than the newest counted:
        the forecast of pass k then uses the passes within history_days before it, through prefix
        sums. Otherwise the passes are taken one by one.
        """
        stamps = np.asarray(passes.stamp_ns, np.int64)
        k = self.kept
        if len(stamps) and (np.any(np.diff(stamps) < 0) or stamps[0] < self.newest_ns):
            return self._history_one_by_one(passes)
        # Views, unchanged by the passes counted and dropped below (RowQueue): nothing here costs in
        # proportion to the passes kept.
        kept_stamps, kept_axles_before, kept_before = k.stamp_ns, self._axles_before.rows, self._growth_before.rows
        axle_total, in_time_order = self._axle_total, k.in_time_order
        before = self.snapshot()
        counted, (steps, summed) = self._advance(passes)
        new = passes.take(counted)
        m, k0 = len(new), len(kept_stamps)
        # Pass k's window: the kept then the new passes from the first stamped within history_days.
        # In time order it starts among the kept passes, or (all of them older) among the new ones.
        end = k0 + np.arange(1, m + 1)                                   # one past pass k
        opens = new.stamp_ns - self.history_ns
        if in_time_order:
            start = np.searchsorted(kept_stamps, opens, side="left")
            in_new = start == k0
            start[in_new] = k0 + np.searchsorted(new.stamp_ns, opens[in_new], side="left")
        else:  # a late pass was kept: searched as one array, as before it was kept
            start = np.searchsorted(np.concatenate([kept_stamps, new.stamp_ns]), opens, side="left")
            in_new = start >= k0

        def at_start(kept_column: np.ndarray, new_column: np.ndarray) -> np.ndarray:
            """Each window's first pass's value, of the kept then the new passes."""
            return np.where(in_new, new_column[np.where(in_new, start - k0, 0)],
                            kept_column[np.minimum(start, k0 - 1)] if k0 else 0)

        new_axles_before = axle_total + np.concatenate([[0], np.cumsum(new.axle_count)])
        axles = (new_axles_before[1:] - at_start(kept_axles_before, new_axles_before)).astype(float)
        first_stamp = at_start(kept_stamps, new.stamp_ns)
        kernels = corrugation_kernels(self.engine)
        # Of the kept passes' prefix sums, only the rows where windows start (a live pass: one).
        old = np.unique(start[start < k0])
        g_prefix = np.concatenate([kept_before[old], summed])
        at = np.where(start < k0, np.searchsorted(old, start), len(old) + start - k0)
        growth, growth_max = kernels.window_growth(g_prefix, at, len(old) + end - k0, axles)
        span_days = (new.stamp_ns - first_stamp) / NS_PER_DAY
        with np.errstate(divide="ignore", invalid="ignore"):
            rate = np.where((span_days > 0) & (span_days >= self.cfg.min_traffic_days),
                            (end - start - 1) / span_days, np.nan)
        log_amplitude = kernels.band_log_amplitude(steps)
        fc = self._forecasts(steps, growth, rate, axles / (end - start), new.stamp_ns, log_amplitude, growth_max)
        ordinal = np.arange(1, m + 1)
        return Trajectory(
            index=np.flatnonzero(counted), stamp_ns=new.stamp_ns.copy(), train_id=new.train_id.copy(),
            amplitude=np.exp(log_amplitude), pass_count=before.pass_count + ordinal,
            axle_pass_count=before.axle_pass_count + np.cumsum(new.axle_count),
            total_pass_count=before.total_pass_count + ordinal, forecast=fc, constants=before)

    def _history_one_by_one(self, passes: PassTable) -> Trajectory:
        rows: list[tuple[int, StateSnapshot, Forecast]] = []
        for i in range(len(passes)):
            if self.advance(passes.take(np.arange(len(passes)) == i))[0]:
                rows.append((i, self.snapshot(), self.forecast()))
        return Trajectory.from_rows(rows, self.snapshot())

    def snapshot(self) -> StateSnapshot:
        """The state as a CorrugationState carries it (without the forecast)."""
        return StateSnapshot(self.newest_ns, self.newest_train_id, self.pass_count, self.axle_pass_count,
                             self.total_pass_count, self.last_grinding_ns, self.bands, self.amplitude,
                             self.threshold, self.grinding_amplitude.copy(), self.k_b.copy(), self.k_b_p10,
                             self.k_b_p90, self.calibration_surveys)

    def _prune(self) -> None:
        k = self.kept
        gone = k.older_than(self.newest_ns - self.history_ns)
        if dropped(gone):
            self._growth_before.drop(gone)
            k.drop(gone)
            if isinstance(gone, slice):
                self._axles_before.drop(gone)
            else:  # the window axles are the kept passes' alone
                self._sum_axles()

    def set_k_b(self, k_b: np.ndarray) -> None:
        """Use K_b per friction state (4,) [-/axle pass] from now on (the kept passes' sums follow)."""
        self.tables.set_k_b(k_b)
        self.resum()

    def resum(self) -> None:
        """Recompute the growth sums from the kept passes (after K_b changes or a load)."""
        k = self.kept
        summed = np.cumsum(np.concatenate([np.zeros((1, *self.log_components.shape)), self._growth(
            k.class_idx, k.friction, k.regime, k.speed, k.axles)]), axis=0)
        self._growth_before, self._growth_total = RowQueue(summed[:-1]), summed[-1].copy()
        self._sum_axles()

    def _sum_axles(self) -> None:
        axles_summed = np.concatenate([[0], np.cumsum(self.kept.axles)])
        self._axles_before, self._axle_total = RowQueue(axles_summed[:-1]), int(axles_summed[-1])

    @property
    def _kept_axles(self) -> int:
        """The kept passes' axles (the running sum's difference)."""
        return self._axle_total - int(self._axles_before.rows[0]) if len(self._axles_before) else 0

    # -- state and forecast ---------------------------------------------------------------------
    def flat(self, band_rms: np.ndarray) -> np.ndarray:
        """ln Z of components sharing each band's r.m.s. [m] equally, (B, P)."""
        return np.repeat(np.log(band_rms / np.sqrt(self.points))[:, None], self.points, axis=1)

    @property
    def amplitude(self) -> np.ndarray:
        """r.m.s. roughness per band [m]."""
        return cstate.band_amplitude(self.log_components)

    @property
    def log_amplitude(self) -> np.ndarray:
        return np.log(self.amplitude)

    @property
    def k_b(self) -> np.ndarray:
        return self.tables.k_b

    @property
    def k_b_p10(self) -> np.ndarray:
        return self.calibration.quantiles(self.cfg.k_b)[0]

    @property
    def k_b_p90(self) -> np.ndarray:
        return self.calibration.quantiles(self.cfg.k_b)[2]

    @property
    def calibration_surveys(self) -> int:
        return self.calibration.fits

    def recent_growth(self) -> np.ndarray:
        """g per component (B, P) [1/axle pass]: the kept passes' growth, averaged per axle pass."""
        if self._kept_axles == 0:
            return np.zeros((len(self.bands), self.points))
        return (self._growth_total - self._growth_before.rows[0]) / self._kept_axles

    def recent_growth_by_state(self) -> np.ndarray:
        """recent_growth() split by friction state (4, B, P) [1/axle pass of all kept passes]."""
        k, out = self.kept, np.zeros((4, *self.log_components.shape))
        if self._kept_axles == 0:
            return out
        growth = self._growth(k.class_idx, k.friction, k.regime, k.speed, k.axles)
        for f in range(4):
            out[f] = growth[k.friction == f + 1].sum(axis=0)
        return out / self._kept_axles

    def forecast_interval(self, after_grinding: bool = False, dry_as_modifier: np.ndarray | None = None
                          ) -> ForecastInterval:
        """P10, P50 and P90 of the days to threshold over the K_b posterior and the bands' levels
        (:func:`.forecast.interval`): at the traffic and weather of the same season a year earlier,
        the modifier's share as recent (:meth:`.season.DailyGrowth.profile`), else the recent traffic.
        after_grinding: of a rail ground now to the configured post-grinding roughness (its
        uncertainty ``post_grinding_uncertainty_db``), the grinding cycle a programme plans with;
        dry_as_modifier: with a friction modifier where the rail was dry, the recent dry passes' growth
        in that state (B, P) [1/axle pass of all kept passes] (:func:`.forecast.with_friction_modifier`)."""
        rate, axles = self.traffic()
        axles = axles if np.isfinite(axles) else self.site.mean_axles_per_train
        days_per_axle_pass = 1.0 / (rate * axles) if np.isfinite(rate) and rate > 0 else np.inf
        recent = self.recent_growth_by_state()
        season = self.season.profile(self.newest_ns, modifier_share(self.kept.friction))
        if dry_as_modifier is not None:
            recent, season = fcst.with_friction_modifier(recent, dry_as_modifier, season, self.k_b)
        if after_grinding:
            state, since = self.flat(self.post_grinding), np.zeros_like(self.growth_by_state)
            level_cov, cross = np.diag(self.post_grinding_var), np.zeros_like(self.level_kb_cov)
        else:
            state, since, level_cov, cross = (self.log_components, self.growth_by_state, self.level_cov,
                                              self.level_kb_cov)
        season = None if season is None else season * self.k_b[None, :, None, None]
        return fcst.interval(state, since, recent, self.calibration, level_cov, cross, self.threshold,
                             days_per_axle_pass, self.newest_ns, season)

    def traffic(self) -> tuple[float, float]:
        """Recent traffic (see :func:`.forecast.traffic`)."""
        return fcst.traffic(self.kept, self.cfg.min_traffic_days)

    def forecast(self, growth: np.ndarray | None = None, passes_per_day: float | None = None,
                 axles_per_train: float | None = None) -> Forecast:
        """Time to the intervention threshold per band at growth g and the traffic.

        growth: g per component (B, P) [1/axle pass] (default: the recent passes');
        passes_per_day: train passes [1/day] (default: the recent rate); axles_per_train [-]
        (default: the recent passes', else the site's traffic-weighted mean).
        """
        g = self.recent_growth() if growth is None else np.asarray(growth, float)
        rate, axles = self.traffic()
        if passes_per_day:
            rate = passes_per_day
        if axles_per_train:
            axles = axles_per_train
        return fcst.single(self._forecasts(self.log_components[None], g[None], np.array([rate]), np.array([axles]),
                                           np.array([self.newest_ns])))

    def _forecasts(self, log_components: np.ndarray, growth: np.ndarray, rate: np.ndarray, axles: np.ndarray,
                   newest_ns: np.ndarray, log_amplitude: np.ndarray | None = None,
                   growth_max: np.ndarray | None = None) -> Forecast:
        return fcst.forecasts(log_components, growth, rate, axles, newest_ns, self.threshold,
                              self.cfg.lead_time_days, self.site.mean_axles_per_train, engine=self.engine,
                              log_amplitude=log_amplitude, growth_max=growth_max)
