"""Measured roughness surveys and grinding events applied to a corrugation state.

A survey re-fits K_b from the growth between two surveys: the measured growth rate of a band is
g_hat = ln(Z2 / Z1) / (n2 - n1) (the UQ seminar paper, see :mod:`rail_monitor.corrugation`;
docs/models.md, "Surveys"). Since ln|1 + K_b x| is K_b x to first order, the scale s minimising
sum (ln(Z2/Z1) - s Delta_model)^2 over the bands measured twice (Delta_model: the state's ln Z
growth since the first survey) scales K_b of every friction state (one survey pair cannot
separate them). A measured band keeps its components' shape, scaled to the measured r.m.s.
"""

from __future__ import annotations

import numpy as np

from rail_monitor.corrugation.estimator import CorrugationEstimator


def match_bands(bands: np.ndarray, wavelength: np.ndarray, amplitude: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Survey values [m] on the state's bands (nominal band centres within 3 %), NaN where absent,
    and the mask of bands matched; ValueError for an unusable survey."""
    wavelength, amplitude = np.asarray(wavelength, float), np.asarray(amplitude, float)
    if wavelength.shape != amplitude.shape or wavelength.ndim != 1:
        raise ValueError("wavelength_m and amplitude_m must be 1-D and the same length")
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
                 stamp_ns: int = 0) -> float | None:
    """Take a measured roughness survey (wavelengths [m], r.m.s. amplitudes [m]): re-fit K_b against
    the previous survey, then set the measured bands to the measurement. Returns the K_b scale
    applied, or None without a fit."""
    z, matched = match_bands(est.bands, wavelength, amplitude)
    scale = None
    both = matched & np.isfinite(est.survey_log_amplitude)
    dm = est.log_amplitude[both] - est.survey_log_amplitude[both]
    if both.any() and np.dot(dm, dm) > 0:  # no passes since the last survey: nothing to fit
        measured = np.log(z[both]) - est.survey_log_amplitude[both]
        s = float(np.dot(measured, dm) / np.dot(dm, dm))
        if s > 0:
            scale = s
            est.set_k_b(est.k_b * s)
    est.log_components[matched] += (np.log(z[matched]) - est.log_amplitude[matched])[:, None]
    est.survey_log_amplitude = np.where(matched, np.log(np.where(matched, z, 1.0)), np.nan)
    est.last_survey_ns = max(est.last_survey_ns, int(stamp_ns))
    return scale


def apply_grinding(est: CorrugationEstimator, stamp_ns: int, wavelength: np.ndarray | None = None,
                   amplitude: np.ndarray | None = None) -> None:
    """Reset after grinding at stamp_ns [ns]: the measured spectrum where given, else the
    post-grinding default."""
    rms = est.post_grinding.copy()
    est.survey_log_amplitude = np.full(len(est.bands), np.nan)
    if wavelength is not None and len(wavelength):
        z, matched = match_bands(est.bands, wavelength, amplitude)
        rms[matched] = z[matched]
        est.survey_log_amplitude[matched] = np.log(z[matched])
    est.log_components = est.flat(rms)
    est.grinding_amplitude = rms
    est.pass_count = est.axle_pass_count = 0
    est.last_grinding_ns = int(stamp_ns)
    est.last_survey_ns = max(est.last_survey_ns, int(stamp_ns))
