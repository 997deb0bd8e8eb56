"""Measured roughness surveys and grinding events applied to a corrugation state.

A survey re-fits K_b per friction state and the bands' levels together: a Bayesian update of ln
K_b and of each band's level at the last survey (:func:`rail_monitor.models.calibration.joint_update`;
docs/models.md, "Calibration") against the state's growth since then, split by friction state. The
state then follows the fitted K_b (its growth since the last survey re-scaled) and the updated
levels (a band keeps its components' shape). The levels' covariance, with each other and with
K_b, is kept: it weighs the next survey and the forecast interval; a grinding resets the levels
and their correlation with K_b.

Order: an event (survey or grinding) applies to the state after every pass stamped at or before
it, and before the first pass stamped later (:func:`split_before`), in batch, in a replay and live
(where an event stamped before a pass already counted can only be applied on arrival).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.models import calibration

KIND_SURVEY, KIND_GRINDING = 1, 2  # as rail_msgs/RoughnessSurvey's KIND_*
KIND_INDIRECT = 3  # the indirect roughness of a window of measured pass-bys (rail_monitor.measured.observer)
MAX_SURVEY_BANDS = 1000  # a trolley survey has tens of 1/3-octave bands


@dataclass(frozen=True)
class MaintenanceEvent:
    """A roughness survey, a grinding event (units as in rail_msgs/RoughnessSurvey) or an indirect
    observation."""

    stamp_ns: int
    kind: int                  # KIND_SURVEY, KIND_GRINDING or KIND_INDIRECT
    wavelength_m: np.ndarray   # band centre wavelengths [m] (a grinding may give none)
    amplitude_m: np.ndarray    # r.m.s. roughness per band [m]
    log_variance: np.ndarray | None = None  # KIND_INDIRECT: variance of each band's ln amplitude [-]


def apply_event(est: CorrugationEstimator, event: MaintenanceEvent) -> calibration.KbPosterior | None:
    """Apply a survey (apply_survey's result) or a grinding (None); ValueError, with the state
    untouched, for an event not newer than the last one applied or an unusable one."""
    if event.stamp_ns < 0:
        raise ValueError("stamp before 1970")
    if event.stamp_ns <= est.last_survey_ns:
        raise ValueError("not newer than the last survey or grinding applied")
    if event.kind == KIND_SURVEY:
        return apply_survey(est, event.wavelength_m, event.amplitude_m, event.stamp_ns)
    if event.kind == KIND_INDIRECT and event.log_variance is not None:
        return apply_survey(est, event.wavelength_m, event.amplitude_m, event.stamp_ns, event.log_variance)
    if event.kind == KIND_GRINDING:
        apply_grinding(est, event.stamp_ns, event.wavelength_m, event.amplitude_m)
        return None
    raise ValueError(f"unknown kind {event.kind}")


def split_before(stamps_ns: np.ndarray, event_ns: int) -> int:
    """How many of the passes (stamps [ns], in stream order) come before an event at event_ns:
    those before the first pass stamped later than it."""
    later = np.asarray(stamps_ns) > event_ns
    return int(np.argmax(later)) if later.any() else len(later)


def in_time_order(events: Sequence[MaintenanceEvent]) -> list[MaintenanceEvent]:
    """The events sorted by stamp (a stable sort: equal stamps keep their order)."""
    return sorted(events, key=lambda e: e.stamp_ns)


def match_bands(bands: np.ndarray, wavelength: np.ndarray, amplitude: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Survey values [m] on the state's bands (nominal band centres within 3 %), NaN where absent,
    and the mask of bands matched; ValueError for an unusable survey."""
    wavelength, amplitude = np.asarray(wavelength, float), np.asarray(amplitude, float)
    if wavelength.shape != amplitude.shape or wavelength.ndim != 1:
        raise ValueError("wavelength_m and amplitude_m must be 1-D and the same length")
    if len(wavelength) > MAX_SURVEY_BANDS:
        raise ValueError(f"more than {MAX_SURVEY_BANDS} wavelengths: not a roughness survey")
    if not (np.all(np.isfinite(amplitude)) and np.all(amplitude > 0) and np.all(wavelength > 0)):
        raise ValueError("survey wavelengths and amplitudes must be finite and positive")
    out = np.full(len(bands), np.nan)
    for lam, z in zip(wavelength, amplitude, strict=True):
        i = int(np.argmin(np.abs(np.log(bands / lam))))
        if abs(np.log(bands[i] / lam)) < 0.03:
            out[i] = z
    matched = np.isfinite(out)
    if not matched.any():
        raise ValueError("no survey wavelength matches a band of the state")
    return out, matched


def apply_survey(est: CorrugationEstimator, wavelength: np.ndarray, amplitude: np.ndarray,
                 stamp_ns: int = 0, log_variance: np.ndarray | None = None) -> calibration.KbPosterior | None:
    """Take a measured roughness survey (wavelengths [m], r.m.s. amplitudes [m]): re-fit K_b from
    the growth since the last survey together with every band's level. Returns the posterior of K_b
    after the fit, or None where the survey cannot inform it (no growth since the last survey and
    no measured level correlated with K_b).
    log_variance: each band's variance of ln amplitude [-] (an indirect observation; default the
    site's survey uncertainty), which also leaves the last survey's spectrum as it was."""
    z, matched = match_bands(est.bands, wavelength, amplitude)
    measured = np.log(z[matched])
    noise_var = est.survey_var
    if log_variance is not None:
        noise_var = match_bands(est.bands, wavelength, log_variance)[0][matched]
    growth = est.growth_by_state
    # a survey informs K_b through the growth since the last one, or through a measured level that
    # earlier surveys left correlated with it; else the posterior stays as it was
    informed = bool(np.any(growth[:, matched] != 0.0) or np.any(est.level_kb_cov[matched] != 0.0))
    start = est.log_components - growth.sum(axis=0)
    fit = calibration.joint_update(est.calibration, est.level_cov, est.level_kb_cov, start, growth, matched,
                                   measured, noise_var)
    delta = fit.delta if informed else np.zeros_like(fit.delta)
    est.log_components = start + fit.shift[:, None] + np.einsum("f,fbp->bp", np.exp(delta), growth)
    est.level_cov, est.level_kb_cov = fit.level_cov, fit.cross
    if informed:
        est.calibration = fit.posterior
        est.set_k_b(fit.posterior.k_b(est.cfg.k_b))
    if log_variance is None:
        est.survey_log_amplitude = np.where(matched, np.log(np.where(matched, z, 1.0)), np.nan)
    est.growth_by_state[:] = 0.0
    est.last_survey_ns = max(est.last_survey_ns, int(stamp_ns))
    return fit.posterior if informed else None


def apply_grinding(est: CorrugationEstimator, stamp_ns: int, wavelength: np.ndarray | None = None,
                   amplitude: np.ndarray | None = None) -> None:
    """Reset after grinding at stamp_ns [ns]: the measured spectrum where given, else the
    post-grinding default."""
    rms = est.post_grinding.copy()
    matched = np.zeros(len(est.bands), bool)
    if wavelength is not None and len(wavelength):
        z, matched = match_bands(est.bands, wavelength, amplitude)  # before any change: a refusal leaves the state
        rms[matched] = z[matched]
    est.survey_log_amplitude = np.where(matched, np.log(rms), np.nan)
    est.log_components = est.flat(rms)
    est.growth_by_state[:] = 0.0
    level_var = est.post_grinding_var.copy()
    level_var[matched] = est.survey_var
    est.level_cov, est.level_kb_cov = np.diag(level_var), np.zeros_like(est.level_kb_cov)
    est.grinding_amplitude = rms
    est.pass_count = est.axle_pass_count = 0
    est.last_grinding_ns = int(stamp_ns)
    est.last_survey_ns = max(est.last_survey_ns, int(stamp_ns))
