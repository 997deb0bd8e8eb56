"""Retention of a long recording (McapBagWriter): a disk budget, an age limit, metadata.yaml kept
current at every split so a power cut leaves a bag that opens (issue 21)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from rail_monitor.bagio.integrity import check_bag
from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.reader import read_bag_passes, salvage_bag_passes
from rail_monitor.codec.cdr import serialize
from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.timeutil import NS_PER_DAY, NS_PER_S
from rail_monitor.messages.fields import train_pass_fields

TOPIC = "/curve_250/train_pass"
TYPE = "rail_msgs/msg/TrainPass"


def _pass(i: int, t0_ns: int, step_ns: int) -> tuple[bytes, int]:
    stamp = t0_ns + i * step_ns
    row = dict(stamp_ns=stamp, train_id=f"T{i:07d}-" + "x" * 40, vehicle_class="emu", vehicle_count=3, axle_count=0,
               speed_mps=19.0 + (i % 7), angle_of_attack_rad=0.004, wheel_load_n=0.0, friction_state=1,
               train_length_m=0.0)
    return serialize(TYPE, train_pass_fields(row, "curve_250")), stamp


def _write(writer: McapBagWriter, n: int, t0_ns: int = 1_790_000_000 * NS_PER_S, step_ns: int = 60 * NS_PER_S,
           start: int = 0) -> None:
    for i in range(start, start + n):
        data, stamp = _pass(i, t0_ns, step_ns)
        writer.write(TOPIC, data, stamp)


def _folder_bytes(folder: Path) -> int:
    return sum(p.stat().st_blocks * 512 for p in folder.iterdir())


def _opens_with_both_readers(folder: Path) -> int:
    """Messages in the bag as rosbags reads it; each listed file also read by the mcap library."""
    with AnyReader([folder]) as reader:
        n = sum(1 for _ in reader.messages())
    for f in sorted(folder.glob("*.mcap")):
        with open(f, "rb") as stream:
            assert sum(1 for _ in make_reader(stream).iter_messages()) > 0
    return n


def test_a_disk_budget_holds_on_a_tmpfs_of_that_size(tmpfs):
    # The budget is the whole tmpfs: one byte past it would be ENOSPC, a failed write.
    budget = 1 << 20
    disk = tmpfs(budget)
    writer = McapBagWriter(disk / "bag", compression="none", chunk_size=16 * 1024, max_file_bytes=128 * 1024,
                           max_total_bytes=budget)
    writer.add_topic(TOPIC, TYPE)
    total = 0
    for _ in range(40):  # about 10x the budget
        _write(writer, 500, start=total)
        total += 500
        assert _folder_bytes(disk / "bag") <= budget and not writer.error
    folder = writer.close()
    assert writer.deleted and _folder_bytes(folder) <= budget
    kept = read_bag_passes(folder)  # the strict reader: metadata, summaries and counts agree
    # What is kept is the newest part of the recording, whole and in order.
    first = int(kept.train_id[0][1:8])
    assert kept.train_id.tolist() == [f"T{i:07d}-" + "x" * 40 for i in range(first, total)]
    assert _opens_with_both_readers(folder) == len(kept)
    assert writer.message_count == total  # every message was written once; retention removed the oldest


def test_an_age_limit_keeps_the_files_with_recent_messages(tmp_path):
    writer = McapBagWriter(tmp_path / "bag", max_file_duration_ns=NS_PER_DAY, max_age_ns=3 * NS_PER_DAY)
    writer.add_topic(TOPIC, TYPE)
    _write(writer, 24 * 10, step_ns=3600 * NS_PER_S)  # 10 days, one pass an hour
    folder = writer.close()
    kept = read_bag_passes(folder)
    newest = int(kept.stamp_ns.max())
    assert len(writer.deleted) >= 5
    # every kept file has a message within 3 days of the newest; the oldest kept starts at most 4 days back
    assert newest - int(kept.stamp_ns.min()) <= 4 * NS_PER_DAY
    assert _opens_with_both_readers(folder) == len(kept)


def test_a_power_cut_leaves_the_finished_files_listed_and_the_open_one_salvageable(tmp_path):
    writer = McapBagWriter(tmp_path / "bag", compression="none", chunk_size=8 * 1024, max_file_bytes=64 * 1024)
    writer.add_topic(TOPIC, TYPE)
    _write(writer, 2000)
    writer.flush()
    cut = tmp_path / "after_power_cut"
    shutil.copytree(writer.folder, cut)  # the folder as the disk holds it: no close, no final metadata
    writer.close()
    on_disk = sorted((p.name for p in cut.glob("*.mcap")), key=lambda n: int(n.rsplit("_", 1)[1].split(".")[0]))
    meta = yaml.safe_load((cut / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["relative_file_paths"] == on_disk[:-1] and len(on_disk) >= 3
    with AnyReader([cut]) as reader:  # rosbags opens it: the finished files, as metadata.yaml lists them
        assert sum(1 for _ in reader.messages()) == meta["message_count"] > 0
    with pytest.raises(InputError, match=r"was being written when the recording stopped.*--salvage"):
        check_bag(cut)
    salvaged, report = salvage_bag_passes(cut)
    assert 0 < len(salvaged) <= 2000 and report.cut_off == 1


@pytest.mark.parametrize(("kw", "says"), [
    ({"max_total_bytes": 1 << 20}, "needs files split by size"),
    ({"max_total_bytes": 300 * 1024, "max_file_bytes": 128 * 1024}, "at least twice"),
    ({"max_age_ns": NS_PER_DAY}, "needs files split"),
])
def test_retention_that_cannot_hold_is_refused(tmp_path, kw, says):
    with pytest.raises(RailMonitorError, match=says):
        McapBagWriter(tmp_path / "bag", **kw)
    assert not (tmp_path / "bag").exists()
