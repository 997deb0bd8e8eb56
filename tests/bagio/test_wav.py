"""WAV files of a station (rail_monitor.bagio.wav): scaled to full scale, one channel, refused in
one line when unusable."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.io import wavfile

from rail_monitor.bagio.wav import read_wav
from rail_monitor.core.errors import InputError


@pytest.mark.parametrize(("dtype", "full_scale"), [(np.int16, 32768.0), (np.int32, 2.0**31), (np.float32, 1.0)])
def test_each_sample_format_reads_in_full_scale_units(tmp_path, dtype, full_scale):
    x = np.array([0.5, -0.25, 0.125, -1.0])
    path = tmp_path / "a.wav"
    wavfile.write(path, 48_000, (x * full_scale).astype(dtype) if dtype != np.float32 else x.astype(dtype))
    fs, samples = read_wav(path)
    assert fs == 48_000.0 and np.allclose(samples, x, atol=1e-7)


def test_a_channel_is_chosen_and_a_missing_one_refused(tmp_path):
    path = tmp_path / "two.wav"
    wavfile.write(path, 48_000, np.array([[1000, -2000], [3000, -4000]], np.int16))
    assert np.allclose(read_wav(path, channel=1)[1] * 32768, [-2000, -4000])
    with pytest.raises(InputError, match="channel 2 does not exist"):
        read_wav(path, channel=2)


def test_a_rate_too_low_for_the_10_khz_band_is_refused(tmp_path):
    path = tmp_path / "low.wav"
    wavfile.write(path, 16_000, np.zeros(100, np.int16))
    with pytest.raises(InputError, match="at least 25600 Hz"):
        read_wav(path)


def test_a_damaged_wav_is_one_line_naming_it(tmp_path):
    path = tmp_path / "cut.wav"
    wavfile.write(path, 48_000, np.zeros(1000, np.int16))
    path.write_bytes(path.read_bytes()[:30])
    with pytest.raises(InputError) as caught:
        read_wav(path)
    assert str(path) in str(caught.value) and "\n" not in str(caught.value)
