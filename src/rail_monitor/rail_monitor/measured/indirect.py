"""Indirect rail roughness from measured pass-by noise, in the spirit of CEN/TR 16891:2016
(Railway applications - Acoustics - Measurement method for combined roughness, track decay rates
and transfer functions): the combined effective roughness follows from the pass-by spectrum and
the transfer functions, here the model's. It is labelled indirect, with its uncertainty; it is
never an EN 15610 (direct) measurement.

Rolling noise in a band is proportional to the combined effective roughness energy (CNOSSOS-EU,
Directive 2015/996 Annex II, eq. 2.3.6: L_R,TOT = 10 lg(10^(L_r,rail/10) + 10^(L_r,veh/10)) + A3),
so a band's residual r (measured minus predicted, dB) scales that energy by 10^(r/10). With the
rail's share s of the predicted combined energy (RollingNoiseModel.rail_share) and the wheels as
the model has them, the rail's energy is scaled by 1 + x, where y = 10^(r/10) - 1 = s x per pass.
Over many passes of several classes, whose wheels differ (disc-braked wheels leave the rail most
of the combined roughness), x is the least-squares fit through the origin, x = sum(s y) / sum(s^2),
per wavelength band of the corrugation state (each pass and noise band at lambda = v / f). The
indirect rail level is the model's rail level plus 10 lg(1 + x). Its standard uncertainty is the
fit's standard error (delta method) and the prediction's own band uncertainty
(``residual.prediction_sd_db``) added in quadrature: with the model's transfer functions in place
of measured ones, a transfer error reads as roughness.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

DB_PER_LN = 10.0 / math.log(10.0)
MIN_PASSES = 20  # per wavelength band, for an estimate


@dataclass(frozen=True)
class IndirectRoughness:
    """Indirect rail roughness per wavelength band (units in the names)."""

    wavelength_m: np.ndarray     # (K,) band centres [m]
    level_db: np.ndarray         # (K,) indirect rail roughness [dB re 1 um]; NaN: no estimate
    sd_db: np.ndarray            # (K,) its standard uncertainty [dB]
    model_db: np.ndarray         # (K,) the model's rail roughness [dB re 1 um]
    passes: np.ndarray           # (K,) pass-bands used [-]
    rail_share: np.ndarray       # (K,) mean rail share of the combined roughness [-]

    @property
    def amplitude_m(self) -> np.ndarray:
        """The indirect level as an r.m.s. amplitude [m] (L = 20 lg(Z / 1 um))."""
        return 1e-6 * 10.0 ** (self.level_db / 20.0)


def indirect_rail_roughness(residual_db: np.ndarray, share: np.ndarray, speed_mps: np.ndarray, band_hz: np.ndarray,
                            wavelength_m: np.ndarray, model_db: np.ndarray, prediction_sd_db: float
                            ) -> IndirectRoughness:
    """Residuals (N, B) [dB] and rail shares (N, B) [-] of N passes at speeds (N,) [m/s] on noise
    bands (B,) [Hz], onto wavelength bands (K,) [m] whose model rail level is model_db (K,)
    [dB re 1 um]. A pass-band counts where both are finite; a wavelength band needs MIN_PASSES."""
    lam = np.asarray(speed_mps, float)[:, None] / np.asarray(band_hz, float)[None, :]
    octaves = np.abs(np.log2(lam[..., None] / np.asarray(wavelength_m, float)))
    k = np.argmin(octaves, axis=-1)
    use = (np.take_along_axis(octaves, k[..., None], axis=-1)[..., 0] <= 1.0 / 6.0) \
        & np.isfinite(residual_db) & np.isfinite(share) & (share > 0)
    y = np.expm1(np.where(use, residual_db, 0.0) / DB_PER_LN)
    kk = len(wavelength_m)
    n = np.bincount(k[use], minlength=kk)
    ss = np.bincount(k[use], weights=share[use] ** 2, minlength=kk)
    sy = np.bincount(k[use], weights=share[use] * y[use], minlength=kk)
    mean_share = np.bincount(k[use], weights=share[use], minlength=kk)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = sy / ss
        err = y[use] - share[use] * x[k[use]]
        var = np.bincount(k[use], weights=err**2, minlength=kk) / np.maximum(n - 1, 1) / ss
        ok = (n >= MIN_PASSES) & (1.0 + x > 0)
        level = np.where(ok, model_db + DB_PER_LN * np.log1p(np.where(ok, x, 0.0)), np.nan)
        fit_db = DB_PER_LN * np.sqrt(var) / (1.0 + x)
        sd = np.where(ok, np.hypot(fit_db, prediction_sd_db), np.nan)
        return IndirectRoughness(np.asarray(wavelength_m, float), level, sd, np.asarray(model_db, float), n,
                                 mean_share / np.maximum(n, 1))
