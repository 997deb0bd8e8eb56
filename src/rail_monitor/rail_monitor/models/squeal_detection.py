"""Curve squeal detected in a recorded pass-by, and told from flanging noise.

Squeal is tonal: one wheel's axial mode, between about 400 Hz and 10 kHz, heard for as long as the
wheelset stays unstable. Flanging noise is broadband and high-pitched, with no single tone. The pass
is cut into frames (0.2 s, half overlapping). In each frame the tonal components between 400 Hz
and 10 kHz are found as models.tonality finds them (ISO/PAS 20065); a frame squeals when its
strongest tone's audibility reaches ``min_audibility_db``. Consecutive squealing frames whose tones
stay within half a critical band of the frame before (a squeal glides with the Doppler shift as the
wheel passes) make a squeal, lasting (frames - 1) x hop (a tone partly
filling the frames at its ends is found in them too; half a frame more at an end of the pass, where
the frames are cut); the pass squeals when its longest squeal lasts
``min_duration_s``. A frame with no such tone but with more power in the 4-10 kHz bands than in the
400 Hz-4 kHz bands is a flanging frame; the pass flanges when its flanging frames last
``min_duration_s`` together.

The defaults are choices, not published thresholds: an audibility of 6 dB (a tone clearly above its
masking threshold; ISO/PAS 20065 calls any positive audibility audible) held for 0.5 s.

References
----------
.. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
   Elsevier, 2009, the chapter on curve squeal (squeal: tonal, at the wheel's axial modes; flanging noise:
   broadband, high frequency).
.. [2] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones in
   noise - Engineering method*.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from rail_monitor.models import tonality

FRAME_S = 0.2
LOW_HZ, HIGH_HZ, SPLIT_HZ = 400.0, 10_000.0, 4_000.0


@dataclass(frozen=True)
class SquealDetection:
    squeal: bool
    frequency_hz: float     # the longest squeal's tone (its strongest frame's) [Hz]; NaN without one
    level_db: float         # its tone level, energy mean over the squeal's frames [dB re 20 uPa]; NaN
    duration_s: float       # the longest squeal [s] (0 without one)
    share: float            # duration_s over the pass's time [-]
    flanging: bool
    flanging_s: float       # frames judged flanging, together [s]


def detect_squeal(pressure_pa: ArrayLike, fs_hz: float, start_s: float | None = None, end_s: float | None = None,
                  min_duration_s: float = 0.5, min_audibility_db: float = 6.0) -> SquealDetection:
    """Squeal and flanging noise in a pass of a calibrated record (module docstring).

    Parameters
    ----------
    pressure_pa, fs_hz, start_s, end_s : array_like, float, float, float
        As for :func:`rail_monitor.models.iso3095.passby_levels`: the record [Pa], its sampling
        rate [Hz] and the pass within it [s] (default: the whole record).
    min_duration_s : float
        Shortest squeal counted [s].
    min_audibility_db : float
        A frame squeals when its strongest tone's audibility reaches this [dB].

    Returns
    -------
    SquealDetection
        Squeal or not, its tone's frequency [Hz], level [dB re 20 uPa], duration [s] and share [-];
        flanging or not and its time [s].

    References
    ----------
    .. [1] D. J. Thompson, *Railway Noise and Vibration: Mechanisms, Modelling and Means of Control*,
       Elsevier, Oxford, 2009, chapter 9 (squeal tonal, at the wheel's axial modes; flanging broadband).
    .. [2] ISO/PAS 20065:2016, *Acoustics - Objective method for assessing the audibility of tones
       in noise - Engineering method*.
    """
    p = np.asarray(pressure_pa, float)
    i1 = 0 if start_s is None else round(start_s * fs_hz)
    i2 = len(p) if end_s is None else round(end_s * fs_hz)
    if not 0 <= i1 < i2 <= len(p):
        raise ValueError("the pass window is not inside the record")
    n, hop = round(FRAME_S * fs_hz), round(FRAME_S * fs_hz / 2)
    starts = range(i1, max(i2 - n, i1) + 1, hop)
    frames = []  # (strongest tone or None, flanging)
    for s in starts:
        part = p[s:s + n]
        found = [t for t in tonality.tones(part, fs_hz, LOW_HZ, HIGH_HZ, resolution_hz=1.0 / FRAME_S)
                 if t.audibility_db >= min_audibility_db]
        tone = max(found, key=lambda t: t.audibility_db) if found else None
        frames.append((tone, tone is None and _high_share(part, fs_hz) > 0.5))
    hop_s = hop / fs_hz
    best: list[tonality.Tone] = []
    best_at = run_at = 0
    run: list[tonality.Tone] = []
    for k, (tone, _) in enumerate(frames):
        if tone is not None and run and abs(tone.frequency_hz - run[-1].frequency_hz) <= \
                tonality.critical_bandwidth_hz(run[-1].frequency_hz) / 2:
            run.append(tone)
        else:
            run, run_at = ([tone], k) if tone is not None else ([], k)
        if len(run) > len(best):
            best, best_at = list(run), run_at
    # A tone of duration D inside the pass fills D / hop + 1 half-overlapping frames (it is found in
    # those it partly fills); at the pass's ends its frames are cut, and half a frame is added back.
    ends = (best_at == 0) + (best_at + len(best) == len(frames))
    duration = (len(best) - 1) * hop_s + ends * FRAME_S / 2 if best else 0.0
    flanging_s = sum(flanges for _, flanges in frames) * hop_s
    pass_s = (i2 - i1) / fs_hz
    squeals = duration >= min_duration_s
    strongest = max(best, key=lambda t: t.level_db) if squeals else None
    return SquealDetection(
        squeal=squeals, frequency_hz=strongest.frequency_hz if strongest else float("nan"),
        level_db=float(10 * np.log10(np.mean([10 ** (t.level_db / 10) for t in best]))) if squeals else float("nan"),
        duration_s=duration if squeals else 0.0, share=min(duration / pass_s, 1.0) if squeals else 0.0,
        flanging=flanging_s >= min_duration_s, flanging_s=flanging_s)


def _high_share(frame: np.ndarray, fs_hz: float) -> float:
    """Power in SPLIT_HZ-HIGH_HZ over power in LOW_HZ-HIGH_HZ of a frame [-] (0 for silence)."""
    f, psd = tonality.density(frame, fs_hz, 1.0 / FRAME_S)
    high = psd[(f >= SPLIT_HZ) & (f <= HIGH_HZ)].sum()
    total = psd[(f >= LOW_HZ) & (f <= HIGH_HZ)].sum()
    return float(high / total) if total > 0 else 0.0
