"""Measured pass-by noise of simulated passes: the model's prediction plus what differs at a real
station (no rclpy; the simulate command and the tests call it).

Each class has a fleet of vehicles; a train runs ``vehicle_count`` of its class's fleet, drawn at
random per pass (consists are re-formed). Every vehicle has its own wheel-roughness offset at
500-2000 Hz, normal with ``wheel_spread_db``; ``defective`` vehicles (wheel flats) carry
``defect_db`` more. A train's band level there is the energy mean of its vehicles' offsets added
to the prediction (each vehicle is heard for the same share of the pass-by time). Every band also
gets the day's weather offset (normal, ``weather_sd_db``, one per day: temperature and wind
change propagation and rail roughness alike) and the instrument's error (normal, the standard
uncertainty of its IEC 61672-1 class, rail_monitor.measured.residuals.INSTRUMENT_SD_DB). The
single numbers move with the A-weighted total; a vehicle segment's LpAeq is the train's with
that vehicle's offset alone, plus the instrument's error. The station's squeal flag is the given
squealing, wrong on a share of passes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rail_monitor.core.passes import PassTable
from rail_monitor.core.timeutil import NS_PER_DAY
from rail_monitor.measured.records import Measurement
from rail_monitor.measured.residuals import INSTRUMENT_SD_DB, MID_BAND_HZ
from rail_monitor.models.iec61260 import band_index
from rail_monitor.models.levels import a_weighted_total, energy_sum


@dataclass(frozen=True)
class MeasuredSeries:
    """Simulated measurements, one per pass given, and the truth behind them."""

    measurements: list[Measurement]
    defective: frozenset[str]              # ids of the vehicles with a wheel defect
    vehicles: list[tuple[str, ...]]        # per measurement, its vehicles in running order
    squealers: frozenset[str] = frozenset()  # ids of the vehicles that squeal more than their class


def simulate_measurements(passes: PassTable, lp_db: np.ndarray, lpaeq_tp_dba: np.ndarray, lpafmax_dba: np.ndarray,
                          tel_dba: np.ndarray, band_hz: np.ndarray, receiver_m: tuple[float, float], seed: int,
                          fleet_per_class: int = 40, defective: int = 4, defect_db: float = 12.0,
                          wheel_spread_db: float = 1.0, weather_sd_db: float = 0.5,
                          instrument_class: int = 1, squealing: np.ndarray | None = None,
                          squeal_error: float = 0.02, squeal_hz: np.ndarray | None = None,
                          squeal_db: np.ndarray | None = None, squeal_sd_db: float = 1.5, squealers: int = 0,
                          squealer_rate: float = 0.5) -> MeasuredSeries:
    """Measurements of passes (rows matching the predictions: lp_db (N, B) [dB] on band_hz [Hz],
    the single numbers (N,) [dB(A)]) at receiver_m (distance, height) [m]. squealing: whether
    each pass squeals (the squeal model's prediction, say); the station's flag is that, wrong on
    a share squeal_error of passes (none squeal without it). squeal_hz, squeal_db: each pass's
    squeal tone [Hz] and its level at the microphone [dB re 20 uPa], measured (with an error of sd
    squeal_sd_db) on the passes that squeal and are flagged; not measured (NaN) without them.
    squealers: vehicles (drawn from the fleets) whose train squeals besides, on a share
    squealer_rate of their passes (a wheel that squeals more than its class: flagged, its tone
    not measured)."""
    rng = np.random.Generator(np.random.PCG64(seed))
    classes = sorted(set(passes.vehicle_class.tolist()))
    fleets = {c: [f"{c.upper()}-V{k:03d}" for k in range(fleet_per_class)] for c in classes}
    every = [v for c in classes for v in fleets[c]]
    offset = dict(zip(every, rng.normal(0.0, wheel_spread_db, len(every)).tolist(), strict=True))
    bad = frozenset(rng.choice(every, size=min(defective, len(every)), replace=False).tolist())
    for v in bad:
        offset[v] += defect_db
    mid = (band_hz >= MID_BAND_HZ[0] * 0.98) & (band_hz <= MID_BAND_HZ[1] * 1.02)
    x = band_index(band_hz)
    sd = INSTRUMENT_SD_DB[instrument_class]
    days = (passes.stamp_ns // NS_PER_DAY).astype(np.int64)
    weather = dict(zip(np.unique(days).tolist(), rng.normal(0.0, weather_sd_db, len(np.unique(days))).tolist(),
                       strict=True))
    out, consists = [], []
    flags = np.zeros(len(passes), bool) if squealing is None else np.asarray(squealing, bool).copy()
    truly = flags.copy()
    flags ^= rng.random(len(passes)) < (0.0 if squealing is None else squeal_error)
    heard = flags & truly & (squeal_db is not None)
    tone_rng = np.random.Generator(np.random.PCG64([seed, 55]))  # its own stream: the rest as without tones
    tone_db = np.where(heard, (squeal_db if squeal_db is not None else 0.0)
                       + tone_rng.normal(0.0, squeal_sd_db, len(passes)), np.nan)
    tone_hz = np.where(heard, squeal_hz if squeal_hz is not None else np.nan, np.nan)
    loud = frozenset(tone_rng.choice(every, size=min(squealers, len(every)), replace=False).tolist()
                     if squealers else ())
    for i in range(len(passes)):
        fleet = fleets[passes.vehicle_class[i]]
        n = int(min(max(passes.vehicle_count[i], 1), len(fleet)))
        vehicles = tuple(rng.choice(fleet, size=n, replace=False).tolist())
        if loud and not loud.isdisjoint(vehicles) and tone_rng.random() < squealer_rate:
            flags[i] = True
        o = np.array([offset[v] for v in vehicles])
        base = lp_db[i] + weather[int(days[i])]
        leq = base + mid * (energy_sum(o) - 10.0 * np.log10(n)) + rng.normal(0.0, sd, len(band_hz))
        shift = float(a_weighted_total(leq, x) - a_weighted_total(lp_db[i], x))
        own = a_weighted_total(base[None, :] + mid[None, :] * o[:, None], x) + rng.normal(0.0, sd, n)
        out.append(Measurement(int(passes.stamp_ns[i]), str(passes.train_id[i]), receiver_m[0], receiver_m[1],
                               instrument_class, band_hz.copy(), leq, float(lpaeq_tp_dba[i]) + shift,
                               float(lpafmax_dba[i]) + shift, float(tel_dba[i]) + shift, bool(flags[i]), vehicles,
                               own, squeal_frequency_hz=float(tone_hz[i]), squeal_level_db=float(tone_db[i])))
        consists.append(vehicles)
    return MeasuredSeries(out, bad, consists, loud)


def true_values(values: dict, true_creep: dict[str, tuple[float, float]] | None = None) -> dict:
    """The site's values with the true rail's creep curves (friction state name -> (k1, k2))."""
    out = dict(values)
    for state, (k1, k2) in (true_creep or {}).items():
        out[f"contact.creep.{state}.k1"], out[f"contact.creep.{state}.k2"] = float(k1), float(k2)
    return out


def station_on_true_rail(passes: PassTable, values: dict, k_b_factor: float, seed: int,
                         true_creep: dict[str, tuple[float, float]] | None = None, squealers: int = 0
                         ) -> MeasuredSeries:
    """A station measuring every valid pass of a true rail whose K_b is the configured one times
    k_b_factor and whose creep curves are true_creep's where given (state name -> (k1, k2)), with
    ``squealers`` vehicles that squeal more than their class (simulate_measurements),
    kept from the fitting (CNOSSOS-EU's prediction on that rail, with simulate_measurements'
    deviations; its squeal flag the squeal model's risk medium or above there, with the tone's
    frequency and level, spread from the squeal model's receiver to the microphone)."""
    from rail_monitor.batch.run import run_models
    from rail_monitor.core.site import site_from_values
    from rail_monitor.simulation.surveys import true_estimator
    from rail_monitor.squeal.config import squeal_config

    truth_values = true_values(values, true_creep)
    truth = run_models(passes, truth_values,
                       estimator=true_estimator(site_from_values(truth_values), truth_values, k_b_factor))
    p = truth.noise["cnossos"] if "cnossos" in truth.noise else next(iter(truth.noise.values()))
    receiver = truth.receiver
    spread = 20.0 * np.log10(squeal_config(truth_values).receiver_distance_m / receiver.distance_m)
    sq = truth.squeal
    return simulate_measurements(truth.accepted, p.lp_db, p.lpaeq_tp_dba, p.lpafmax_dba, p.tel_dba, p.band_centre_hz,
                                 (receiver.distance_m, receiver.height_m), seed, squealing=sq["risk"] >= 2,
                                 squeal_hz=sq["frequency_hz"], squeal_db=sq["level_db"] + spread,
                                 squealers=squealers)
