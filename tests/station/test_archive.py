"""The station's audio archive (rail_monitor.station.archive): the passes worth hearing kept within
a disk budget, each removal and each pass not kept counted, only its own files ever removed."""

from __future__ import annotations

import json

import pytest

from rail_monitor.core.errors import InputError
from rail_monitor.station.archive import INDEX, LOUDEST, NS_PER_DAY, SQUEAL, SUSPECT, AudioArchive

DAY0 = 20_000 * NS_PER_DAY


def _audio(folder, name: str, size: int = 100):
    folder.mkdir(exist_ok=True)
    path = folder / name
    path.write_bytes(b"x" * size)
    return path


def test_the_loudest_of_each_day_are_kept_and_a_quieter_one_leaves_when_a_louder_comes(tmp_path):
    rec = tmp_path / "recorder"
    a = AudioArchive(tmp_path / "archive", 10_000, loudest_per_day=2)
    for i, level in enumerate([80.0, 85.0, 90.0, 70.0]):
        a.offer(_audio(rec, f"p{i}.wav"), DAY0 + i, f"T{i}", level, squeals=False)
    a.offer(_audio(rec, "next_day.wav"), DAY0 + NS_PER_DAY, "N", 60.0, squeals=False)  # a day of its own
    assert sorted(k.train_id for k in a.kept.values()) == ["N", "T1", "T2"]
    assert sorted(p.name for p in (tmp_path / "archive").glob("*.wav")) == ["next_day.wav", "p1.wav", "p2.wav"]
    assert a.counts["removed: no longer among its day's loudest"] == 1
    assert len(list(rec.iterdir())) == 5  # the recorder's folder is never touched


def test_a_squealing_pass_stays_when_it_leaves_the_loudest_and_the_budget_removes_lowest_oldest_first(tmp_path):
    rec = tmp_path / "recorder"
    a = AudioArchive(tmp_path / "archive", 300, loudest_per_day=1)
    assert a.offer(_audio(rec, "s0.wav"), DAY0, "S0", 90.0, squeals=True) == [SQUEAL, LOUDEST]
    assert a.offer(_audio(rec, "l1.wav"), DAY0 + 1, "L1", 95.0, squeals=False) == [LOUDEST]
    assert a.kept[(DAY0, "S0")].reasons == [SQUEAL]          # no longer the loudest, still squealing
    assert a.offer(_audio(rec, "s2.wav"), DAY0 + 2, "S2", 70.0, squeals=True) == [SQUEAL]
    assert a.used_bytes == 300
    # Full: a fourth squeal removes the lowest reason first (the loudest-only pass), ...
    assert a.offer(_audio(rec, "s3.wav"), DAY0 + 3, "S3", 71.0, squeals=True) == [SQUEAL]
    assert sorted(k.train_id for k in a.kept.values()) == ["S0", "S2", "S3"]
    # ... then the oldest of its own reason; a loudest-only pass cannot displace a squeal: not kept, counted.
    assert a.offer(_audio(rec, "s4.wav"), DAY0 + 4, "S4", 72.0, squeals=True) == [SQUEAL]
    assert sorted(k.train_id for k in a.kept.values()) == ["S2", "S3", "S4"]
    assert a.offer(_audio(rec, "l5.wav"), DAY0 + NS_PER_DAY, "L5", 99.0, squeals=False) == []
    assert a.counts["removed (loudest of its day) to stay within the disk budget"] == 1
    assert a.counts["removed (squeal) to stay within the disk budget"] == 1
    assert a.counts["not kept (loudest of its day): over the disk budget"] == 1
    assert any("L5" in n and "not kept" in n for n in a.take_notes()) and not a.take_notes()
    assert a.used_bytes <= 300 and sum(p.stat().st_size for p in (tmp_path / "archive").glob("*.wav")) <= 300


def test_a_wheel_defect_suspect_outranks_the_loudest_and_is_counted_when_its_audio_is_gone(tmp_path):
    rec = tmp_path / "recorder"
    a = AudioArchive(tmp_path / "archive", 200, loudest_per_day=0)
    assert a.offer(_audio(rec, "q.wav"), DAY0, "Q", 80.0, squeals=False) == []   # nothing to keep it for
    assert a.suspect(rec / "q.wav", DAY0, "Q", 80.0) == [SUSPECT]
    (rec / "q.wav").unlink()
    assert (tmp_path / "archive" / "q.wav").is_file()                            # a copy, not a link
    assert a.suspect(rec / "gone.wav", DAY0 + 1, "G", 80.0) == []
    assert a.counts["suspect's audio no longer at hand"] == 1


def test_the_index_survives_a_restart_and_a_foreign_file_is_never_removed_or_counted(tmp_path):
    rec, folder = tmp_path / "recorder", tmp_path / "archive"
    foreign = _audio(folder, "someone_elses.wav", 10_000)
    a = AudioArchive(folder, 250, loudest_per_day=0)
    for i in range(3):
        a.offer(_audio(rec, f"s{i}.wav"), DAY0 + i, f"S{i}", 80.0, squeals=True)
    b = AudioArchive(folder, 250, loudest_per_day=0)  # a restart
    assert sorted(b.kept) == [(DAY0 + 1, "S1"), (DAY0 + 2, "S2")] and b.used_bytes == 200
    b.offer(_audio(rec, "s3.wav"), DAY0 + 3, "S3", 80.0, squeals=True)
    assert foreign.read_bytes() == b"x" * 10_000
    assert not (folder / "s1.wav").exists() and (folder / "s3.wav").exists()
    (folder / INDEX).write_text(json.dumps([{"name": "../x.wav"}]))
    with pytest.raises(InputError, match=r"index\.json: not this station's archive index") as err:
        AudioArchive(folder, 250, loudest_per_day=0)
    assert "\n" not in str(err.value)
