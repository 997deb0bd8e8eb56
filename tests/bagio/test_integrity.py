"""A bag that disagrees with its own index or metadata is refused, never read as fewer passes with
exit 0; --salvage reads every intact chunk, past damaged ones (rail_monitor.bagio.integrity and
the readers that use it)."""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

import pytest
import yaml

from rail_monitor.bagio.passes_bag import write_passes_bag
from rail_monitor.bagio.reader import bag_info, read_bag_passes, read_passes_reported
from rail_monitor.cli import main
from rail_monitor.core.errors import InputError

from conftest import SAMPLE, SITE_FILE, run_cmd

CHUNK, CHUNK_INDEX, FOOTER, DATA_END = 0x06, 0x08, 0x02, 0x0F


def _frames(data: bytes) -> list[tuple[int, int, int]]:
    """(opcode, record start, content length) of each MCAP record, read from the framing alone."""
    out, pos = [], 8
    while pos + 9 <= len(data):
        opcode, length = struct.unpack_from("<BQ", data, pos)
        out.append((opcode, pos, length))
        if opcode == FOOTER:
            break
        pos += 9 + length
    return out


@pytest.fixture(scope="module")
def small(tmp_path_factory, sample_passes) -> Path:
    """400 passes of the sample in 16 KiB chunks (several chunks, several chunk indexes)."""
    return write_passes_bag(sample_passes.take(slice(0, 400)), tmp_path_factory.mktemp("b") / "small", "curve_250",
                            chunk_size=16 * 1024)


def _copy(bag: Path, tmp_path: Path) -> tuple[Path, Path]:
    out = tmp_path / bag.name
    shutil.copytree(bag, out)
    return out, next(out.glob("*.mcap"))


def _flip(path: Path, offset: int) -> None:
    data = bytearray(path.read_bytes())
    data[offset] ^= 0x5A
    path.write_bytes(bytes(data))


def test_no_flipped_byte_of_the_summary_reads_as_other_passes(small, tmp_path):
    """Every 5th byte from the end of the data section to the end of the file, flipped alone: the
    passes read are the original ones or the read is refused with one line, never fewer or others."""
    whole = read_bag_passes(small)
    mcap = next(small.glob("*.mcap"))
    data = mcap.read_bytes()
    data_end = next(start for opcode, start, _ in _frames(data) if opcode == DATA_END)
    outcomes = {"same": 0, "refused": 0}
    for offset in range(data_end, len(data), 5):
        bag, f = _copy(small, tmp_path / str(offset))
        _flip(f, offset)
        try:
            got = read_bag_passes(bag)
        except InputError as exc:
            assert "\n" not in str(exc)
            outcomes["refused"] += 1
            continue
        assert got.equals(whole), offset
        outcomes["same"] += 1
    assert outcomes["refused"] > 0


def test_a_damaged_chunk_index_or_channel_is_refused_by_every_front_end(small, tmp_path, capsys):
    data = next(small.glob("*.mcap")).read_bytes()
    index = next(start for opcode, start, _ in _frames(data) if opcode == CHUNK_INDEX)
    bag, f = _copy(small, tmp_path)
    _flip(f, index + 9 + 16)  # the chunk's start offset
    with pytest.raises(InputError, match="disagrees with itself"):
        read_bag_passes(bag)
    for argv in (["info", str(bag)], ["batch", str(bag), "--output", str(tmp_path / "out"), "--no-report"],
                 ["export", str(bag), "--site", str(SITE_FILE), "--output", str(tmp_path / "exported")]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(bag) in err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    assert not (tmp_path / "exported").exists()
    r = run_cmd("pass_replayer", "--ros-args", "-p", f"source:={bag}", "-p", "progress:=false", timeout=60)
    assert r.returncode == 2 and "disagrees with itself" in r.stderr and "Traceback" not in r.stderr


def _meta(bag: Path, edit) -> None:
    path = bag / "metadata.yaml"
    doc = yaml.safe_load(path.read_text())
    edit(doc["rosbag2_bagfile_information"])
    path.write_text(yaml.safe_dump(doc))


@pytest.mark.parametrize(("what", "edit", "match"), [
    ("no files listed", lambda m: m.update(relative_file_paths=[]), "lists 0 file"),
    ("a file listed twice", lambda m: m.update(relative_file_paths=m["relative_file_paths"] * 2),
     "lists a file more than once"),
    ("a renamed topic", lambda m: m["topics_with_message_count"][0]["topic_metadata"].update(name="/train_pazz"),
     "on /train_pa"),
    ("a lying topic count", lambda m: m["topics_with_message_count"][0].update(message_count=9999), "9999"),
    ("a lying total", lambda m: m.update(message_count=9999), "9999"),
    # Issue 52: a type its files do not hold, and a start no stamp can hold (2**70 ns crashed `info`).
    ("a lying topic type", lambda m: m["topics_with_message_count"][0]["topic_metadata"].update(
        type="std_msgs/msg/String"), "says topic /train_pass is std_msgs/msg/String, its files hold rail_msgs"),
    ("a start in the year 39381", lambda m: m["starting_time"].update(nanoseconds_since_epoch=2**70),
     "not times a stamp can hold"),
    ("a negative duration", lambda m: m["duration"].update(nanoseconds=-1), "not times a stamp can hold"),
    ("no starting time", lambda m: m.pop("starting_time"), "starting_time"),
])
def test_a_lying_metadata_file_is_refused(small, tmp_path, what, edit, match):
    bag, _ = _copy(small, tmp_path)
    _meta(bag, edit)
    for read in (read_bag_passes, bag_info):
        with pytest.raises(InputError, match=match):
            read(bag)


def test_salvage_skips_a_damaged_chunk_and_reads_every_intact_one(small, tmp_path):
    whole = read_bag_passes(small)
    bag, f = _copy(small, tmp_path)
    data = f.read_bytes()
    chunks = [(start, length) for opcode, start, length in _frames(data) if opcode == CHUNK]
    assert len(chunks) >= 4
    start, length = chunks[1]
    _flip(f, start + 9 + length - 50)  # inside the second chunk's compressed records
    with pytest.raises(InputError, match=r"1 of \d+ chunks damaged"):
        read_bag_passes(bag)
    salvaged, read = read_passes_reported(bag, salvage=True)
    report = read.salvage
    line = report.line(bag)
    assert report.damaged_chunks == 1 and "from the complete chunks" in line and "skipped 1 damaged chunk" in line
    lost = len(whole) - len(salvaged)
    assert 0 < lost < len(whole) / 2                      # the chunks after the damaged one are read
    kept = set(zip(salvaged.stamp_ns.tolist(), salvaged.train_id.tolist(), strict=True))
    assert kept <= set(zip(whole.stamp_ns.tolist(), whole.train_id.tolist(), strict=True))
    assert int(salvaged.stamp_ns.max()) == int(whole.stamp_ns.max())  # the last chunk is intact


def test_salvage_uses_the_summarys_channels_when_the_first_chunk_is_damaged(small, tmp_path):
    """Issue 52: the first chunk holds the data's only schema and channel records; damaged, salvage
    placed none of the later chunks' messages ("salvaged 0 messages"). The summary's copies place
    them now: every pass of every intact chunk comes back."""
    whole = read_bag_passes(small)
    bag, f = _copy(small, tmp_path)
    chunks = [(start, length) for opcode, start, length in _frames(f.read_bytes()) if opcode == CHUNK]
    start, length = chunks[0]
    _flip(f, start + 9 + length - 50)
    salvaged, read = read_passes_reported(bag, salvage=True)
    assert read.salvage.damaged_chunks == 1 and read.salvage.unplaced == 0
    lost = len(whole) - len(salvaged)
    assert 0 < lost < len(whole) / 2 and len(chunks) >= 4
    assert salvaged.equals(whole.take(slice(lost, None)))  # all but the first chunk's passes, as written


def test_the_campaigns_salvage_repro_on_the_sample(tmp_path):
    """The campaign's repro: byte 74 of the sample flipped (inside its first chunk); the second
    chunk's 691 passes come back."""
    bag = tmp_path / "m"
    shutil.copytree(SAMPLE, bag)
    f = bag / "sample_0.mcap"
    data = bytearray(f.read_bytes())
    data[74] ^= 1
    f.write_bytes(bytes(data))
    salvaged, read = read_passes_reported(bag, salvage=True)
    assert read.salvage.damaged_chunks == 1 and len(salvaged) >= 691, read.salvage.line(bag)


def test_the_sample_and_a_recorded_bag_pass_the_checks():
    assert len(read_bag_passes(SAMPLE)) == 8638
    assert bag_info(SAMPLE).message_count == 8638 + 1  # and its friction-modifier applicator's start
