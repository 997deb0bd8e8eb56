"""Indirect rail roughness from measured pass-by noise, in the spirit of CEN/TR 16891:2016
(Railway applications - Acoustics - Measurement method for combined roughness, track decay rates
and transfer functions): the combined effective roughness follows from the pass-by spectrum and
the transfer functions, here the model's. It is labelled indirect, with its uncertainty; it is
never an EN 15610 (direct) measurement.

Rolling noise in a band is proportional to the combined effective roughness energy (CNOSSOS-EU,
Directive 2015/996 Annex II, eq. 2.3.6: L_R,TOT = 10 lg(10^(L_r,rail/10) + 10^(L_r,veh/10)) + A3),
so a band's residual r (measured minus predicted, dB) scales that energy by 10^(r/10). With the
rail's share s of the predicted combined energy (RollingNoiseModel.rail_share) and the wheels as
the model has them, the rail's energy is scaled by 1 + x, where r = 10 lg(1 + s x) per pass. Over
many passes of several classes, whose wheels differ (disc-braked wheels leave the rail most of the
combined roughness), x is the least-squares fit of that in dB (the spread of pass-by levels is
symmetric in dB; an energy mean of them reads high), per wavelength band of the corrugation state
(each pass and noise band at lambda = v / f). The
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
_GN_ITERATIONS = 8
# A band observes the state's growth where the growth is at least this share of the observed rail
# energy: there an error in the energy is at most as large in the amplitude (d ln Z <= d ln E).
MIN_GROWTH_SHARE = 0.5


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


@dataclass
class IndirectPairs:
    """The (wavelength band, rail share, residual) of every pass-band added, in the order added
    (so that passes added one at a time or many at once give the same fit)."""

    band: np.ndarray      # (M,) index of the wavelength band
    share: np.ndarray     # (M,) rail share s [-]
    residual: np.ndarray  # (M,) residual r [dB]
    bands: int

    @classmethod
    def empty(cls, bands: int) -> IndirectPairs:
        return cls(np.zeros(0, np.int64), np.zeros(0), np.zeros(0), bands)

    @property
    def n(self) -> np.ndarray:
        """Pass-bands per wavelength band."""
        return np.bincount(self.band, minlength=self.bands)

    def as_array(self) -> np.ndarray:
        """(3, M): band, share, residual (for a checkpoint)."""
        return np.stack([self.band.astype(float), self.share, self.residual])

    @classmethod
    def from_array(cls, a: np.ndarray, bands: int) -> IndirectPairs:
        a = np.asarray(a, float)
        if a.ndim != 2 or a.shape[0] != 3 or not np.all(np.isfinite(a)) or np.any(a[0] < 0) \
                or np.any(a[0] >= bands) or np.any(a[0] != np.round(a[0])) or np.any(a[1] <= 0):
            raise ValueError("indirect pass-bands have the wrong shape, an unknown band or a share not positive")
        return cls(a[0].astype(np.int64), a[1].copy(), a[2].copy(), bands)

    def add(self, residual_db: np.ndarray, share: np.ndarray, speed_mps: np.ndarray, band_hz: np.ndarray,
            wavelength_m: np.ndarray) -> None:
        """Add N passes' residuals (N, B) [dB] and rail shares (N, B) [-] at speeds (N,) [m/s] on
        noise bands (B,) [Hz] (each pass-band at lambda = v / f, within 1/6 octave of a band centre
        of wavelength_m [m]; both values finite, the share positive)."""
        residual_db, share = np.atleast_2d(residual_db), np.atleast_2d(share)
        if not len(residual_db):
            return
        lam = np.asarray(speed_mps, float)[:, None] / np.asarray(band_hz, float)[None, :]
        octaves = np.abs(np.log2(lam[..., None] / np.asarray(wavelength_m, float)))
        k = np.argmin(octaves, axis=-1)
        use = (np.take_along_axis(octaves, k[..., None], axis=-1)[..., 0] <= 1.0 / 6.0) \
            & np.isfinite(residual_db) & np.isfinite(share) & (share > 0)
        self.band = np.concatenate([self.band, k[use]])
        self.share = np.concatenate([self.share, share[use]])
        self.residual = np.concatenate([self.residual, residual_db[use]])

    def estimate(self, wavelength_m: np.ndarray, model_db: np.ndarray, prediction_sd_db: float) -> IndirectRoughness:
        """The indirect rail roughness on the wavelength bands whose model rail level is model_db
        (K,) [dB re 1 um]; a band needs MIN_PASSES pass-bands. Per band, x minimises
        sum (r - 10 lg(1 + s x))^2: least squares in dB, where the spread of a pass-by level about
        its mean is (wheels, weather, the instrument), so that it does not bias x as an energy
        mean would (E[10^(r/10)] > 10^(E[r]/10)). Gauss-Newton from the energy fit."""
        kk, n = self.bands, self.n
        s, r, k = self.share, self.residual, self.band
        y = np.expm1(r / DB_PER_LN)
        with np.errstate(divide="ignore", invalid="ignore"):
            x = np.bincount(k, weights=s * y, minlength=kk) / np.bincount(k, weights=s * s, minlength=kk)
            largest = np.zeros(kk)
            np.maximum.at(largest, k, s)
            floor = -(1.0 - 1e-9) / np.where(largest > 0, largest, np.inf)  # 1 + s x > 0 on every pass-band
            x = np.maximum(x, floor)
            for _ in range(_GN_ITERATIONS):
                xs = x[k]
                f = DB_PER_LN * np.log1p(s * xs)
                jac = DB_PER_LN * s / (1.0 + s * xs)
                step = np.bincount(k, weights=jac * (r - f), minlength=kk) / np.bincount(k, weights=jac**2,
                                                                                       minlength=kk)
                x = np.maximum(x + step, floor)
            xs = x[k]
            jac = DB_PER_LN * s / (1.0 + s * xs)
            err = r - DB_PER_LN * np.log1p(s * xs)
            var_x = np.bincount(k, weights=err**2, minlength=kk) / np.maximum(n - 1, 1) \
                / np.bincount(k, weights=jac**2, minlength=kk)
            ok = (n >= MIN_PASSES) & (1.0 + x > 0) & np.isfinite(x)
            level = np.where(ok, model_db + DB_PER_LN * np.log1p(np.where(ok, x, 0.0)), np.nan)
            fit_db = DB_PER_LN * np.sqrt(var_x) / (1.0 + x)
            sd = np.where(ok, np.hypot(fit_db, prediction_sd_db), np.nan)
            mean_share = np.bincount(k, weights=s, minlength=kk) / np.maximum(n, 1)
        return IndirectRoughness(np.asarray(wavelength_m, float), level, sd, np.asarray(model_db, float), n, mean_share)


def indirect_rail_roughness(residual_db: np.ndarray, share: np.ndarray, speed_mps: np.ndarray, band_hz: np.ndarray,
                            wavelength_m: np.ndarray, model_db: np.ndarray, prediction_sd_db: float
                            ) -> IndirectRoughness:
    """Residuals (N, B) [dB] and rail shares (N, B) [-] of N passes at speeds (N,) [m/s] on noise
    bands (B,) [Hz], onto wavelength bands (K,) [m] whose model rail level is model_db (K,)
    [dB re 1 um]. A pass-band counts where both are finite; a wavelength band needs MIN_PASSES."""
    pairs = IndirectPairs.empty(len(wavelength_m))
    pairs.add(residual_db, share, speed_mps, band_hz, wavelength_m)
    return pairs.estimate(wavelength_m, model_db, prediction_sd_db)


def state_observation(ind: IndirectRoughness, baseline_db: np.ndarray, post_grinding_m: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
    """The corrugation amplitude an indirect rail level implies [m] and the variance of its ln [-]
    per band (NaN: no observation). The noise model's rail roughness energy is the baseline's plus
    the state's growth since grinding, E = P_base + Z^2 - Z_0^2 (RollingNoiseModel.rail_roughness_db),
    so the observed E_obs gives Z^2 = Z_0^2 + E_obs - P_base, and by the delta method
    var(ln Z) = (E_obs / (2 Z^2))^2 var(ln E_obs). Only bands whose observed growth E_obs - P_base is
    at least MIN_GROWTH_SHARE of E_obs are kept (elsewhere a small energy error is a large amplitude
    error). baseline_db: the baseline rail
    roughness on the bands [dB re 1 um]; post_grinding_m: Z_0 [m]."""
    e_obs = 1e-12 * 10.0 ** (ind.level_db / 10.0)          # [m^2]
    growth = e_obs - 1e-12 * 10.0 ** (np.asarray(baseline_db, float) / 10.0)
    z2 = np.asarray(post_grinding_m, float) ** 2 + growth
    ok = np.isfinite(ind.level_db) & (growth >= MIN_GROWTH_SHARE * e_obs)
    var_ln_e = (ind.sd_db / DB_PER_LN) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        amplitude = np.where(ok, np.sqrt(np.where(ok, z2, 1.0)), np.nan)
        var = np.where(ok, (e_obs / (2.0 * np.where(ok, z2, 1.0))) ** 2 * var_ln_e, np.nan)
    return amplitude, var
