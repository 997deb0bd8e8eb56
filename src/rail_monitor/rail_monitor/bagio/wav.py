"""WAV files of a sound level meter or a station's recorder, read as samples in the file's full scale
(integer formats divided by their full scale; float formats as written)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.io import wavfile

from rail_monitor.core.errors import InputError
from rail_monitor.core.user_file import regular_file

MAX_WAV_BYTES = 4 << 30     # about 6 hours of 48 kHz 32-bit mono
MIN_RATE_HZ = 25_600.0      # a 10 kHz band needs its upper edge (11.2 kHz) below half the rate


def read_wav(path: str | Path, channel: int = 0) -> tuple[float, NDArray[np.float64]]:
    """The sampling rate [Hz] and one channel's samples [full scale] of a WAV file (InputError, one
    line naming the file, for anything that is not a usable recording)."""
    path = Path(path)
    size = regular_file(path, "a WAV file").st_size
    if size > MAX_WAV_BYTES:
        raise InputError(f"{path}: {size} bytes, more than a WAV file may hold here ({MAX_WAV_BYTES} bytes)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", wavfile.WavFileWarning)  # unknown chunks (markers, metadata)
            rate, data = wavfile.read(path)
    except Exception as exc:  # scipy raises ValueError, EOFError, struct.error... for a damaged file
        raise InputError(f"{path}: not a readable WAV file: {(str(exc).splitlines() or [type(exc).__name__])[0]}"
                         ) from None
    if data.ndim == 2:
        if not 0 <= channel < data.shape[1]:
            raise InputError(f"{path}: has {data.shape[1]} channel(s); channel {channel} does not exist")
        data = data[:, channel]
    elif channel != 0:
        raise InputError(f"{path}: has one channel; channel {channel} does not exist")
    if rate < MIN_RATE_HZ:
        raise InputError(f"{path}: sampled at {rate} Hz; the bands up to 10 kHz need at least {MIN_RATE_HZ:g} Hz")
    if not len(data):
        raise InputError(f"{path}: holds no samples")
    if data.dtype.kind == "f":
        samples = data.astype(np.float64)
    elif data.dtype == np.uint8:
        samples = (data.astype(np.float64) - 128.0) / 128.0
    else:
        samples = data.astype(np.float64) / float(-np.iinfo(data.dtype).min)
    if not np.all(np.isfinite(samples)):
        raise InputError(f"{path}: holds samples that are not finite numbers")
    return float(rate), samples
