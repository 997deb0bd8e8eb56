"""Bags: rosbag2-compatible MCAP read by independent readers; sqlite3 input; bad bags; salvage."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import StoragePlugin, Writer

from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.passes_bag import pass_cdr, write_passes_bag
from rail_monitor.bagio.reader import bag_info, read_bag_passes, read_passes, salvage_mcap
from rail_monitor.codec.typestore import TRAIN_PASS, type_hash, typestore
from rail_monitor.core.errors import InputError
from rail_monitor.messages.topics import qos_dict

from conftest import SAMPLE, TOP, run_cmd


def _rosidl_hash(typename: str) -> str:
    """The hash rosidl generated for the type (its .json beside the .msg that colcon installed)."""
    from ament_index_python.packages import get_package_share_directory

    pkg, _, name = typename.split("/")
    doc = json.loads((Path(get_package_share_directory(pkg)) / "msg" / f"{name}.json").read_text())
    return next(h["hash_string"] for h in doc["type_hashes"] if h["type_name"] == typename)


def test_type_hashes_equal_rosidl():
    for name in ("TrainPass", "CorrugationState", "RollingNoise", "SquealPrediction", "WaysideAlert"):
        assert type_hash(f"rail_msgs/msg/{name}") == _rosidl_hash(f"rail_msgs/msg/{name}")


def test_written_bag_decodes_with_rosbags_and_mcap_ros2(tmp_path: Path, sample_passes):
    part = sample_passes.take(slice(0, 300))
    bag = write_passes_bag(part, tmp_path / "b", "curve_250")
    # rosbags (metadata.yaml + MCAP storage)
    with AnyReader([bag]) as r:
        (conn,) = r.connections
        assert conn.msgtype == TRAIN_PASS and conn.msgcount == 300
        assert conn.digest == _rosidl_hash(TRAIN_PASS)
        first = r.deserialize(next(r.messages())[2], TRAIN_PASS)
        assert first.header.frame_id == "curve_250" and first.train_id == part.train_id[0]
    # mcap-ros2-support decodes from the embedded ros2msg schema alone
    with open(next(bag.glob("*.mcap")), "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        decoded = [m for _, _, _, m in reader.iter_decoded_messages()]
        (channel,) = reader.get_summary().channels.values()
    assert len(decoded) == 300
    assert np.allclose([m.speed_mps for m in decoded], part.speed_mps)
    assert [m.train_id for m in decoded] == list(part.train_id)
    assert channel.metadata["topic_type_hash"] == _rosidl_hash(TRAIN_PASS)
    assert yaml.safe_load(channel.metadata["offered_qos_profiles"])[0]["reliability"] == "reliable"
    meta = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["version"] == 9 and meta["message_count"] == 300
    # and our reader gives back exactly what went in
    assert read_bag_passes(bag).equals(part)


def test_schema_carries_full_dependency_text():
    from rail_monitor.codec.typestore import schema_text

    text = schema_text(TRAIN_PASS)
    assert "float64 speed_mps" in text and "[m/s]" in text
    assert "MSG: std_msgs/Header" in text and "MSG: builtin_interfaces/Time" in text
    assert ("=" * 80) in text


def test_sqlite3_bag_input(tmp_path: Path, sample_passes):
    part = sample_passes.take(slice(0, 50))
    ts = typestore()
    path = tmp_path / "sq"
    with Writer(path, version=9, storage_plugin=StoragePlugin.SQLITE3) as w:
        conn = w.add_connection("/train_pass", TRAIN_PASS, typestore=ts)
        for stamp, data in zip(part.stamp_ns, pass_cdr(part, "x"), strict=True):
            w.write(conn, int(stamp), data)
    assert bag_info(path).storage == "sqlite3"
    assert read_passes(path).equals(part)


def test_split_by_size_keeps_every_message(tmp_path: Path, sample_passes):
    data = pass_cdr(sample_passes.take(slice(0, 2000)), "s")
    with McapBagWriter(tmp_path / "split", chunk_size=4096, max_file_bytes=20_000) as w:
        w.add_topic("/train_pass", TRAIN_PASS, [qos_dict()])
        for i, d in enumerate(data):
            w.write("/train_pass", d, 1_000_000_000 + i)
    files = sorted((tmp_path / "split").glob("*.mcap"))
    assert len(files) > 2
    meta = yaml.safe_load((tmp_path / "split" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert meta["relative_file_paths"] == [f.name for f in files]
    assert sum(f["message_count"] for f in meta["files"]) == 2000
    assert len(read_bag_passes(tmp_path / "split")) == 2000


def test_messages_written_together_make_the_same_files_as_one_by_one(tmp_path: Path, sample_passes):
    # split by size inside a block of messages, as at its edges; the files equal byte for byte
    data = pass_cdr(sample_passes.take(slice(0, 700)), "s")
    stamps = [1_000_000_000 + i for i in range(len(data))]
    for name, blocks in (("one", [1] * len(data)), ("many", [1, 37, 200, 3, 459])):
        with McapBagWriter(tmp_path / name / "bag", chunk_size=4096, max_file_bytes=20_000) as w:
            w.add_topic("/train_pass", TRAIN_PASS, [qos_dict()])
            at = 0
            for n in blocks:
                w.write_many("/train_pass", data[at:at + n], stamps[at:at + n])
                at += n
            assert w.written("/train_pass") == len(data)
    one, many = (sorted((tmp_path / name / "bag").glob("*.mcap")) for name in ("one", "many"))
    assert len(one) > 2 and [f.name for f in one] == [f.name for f in many]
    assert all(a.read_bytes() == b.read_bytes() for a, b in zip(one, many, strict=True))


def test_split_by_duration(tmp_path: Path, sample_passes):
    part = sample_passes.take(slice(0, 1000))  # about 10 days
    with McapBagWriter(tmp_path / "d", max_file_duration_ns=2 * 86400 * 10**9) as w:
        w.add_topic("/train_pass", TRAIN_PASS)
        for stamp, d in zip(part.stamp_ns, pass_cdr(part, "s"), strict=True):
            w.write("/train_pass", d, int(stamp))
    meta = yaml.safe_load((tmp_path / "d" / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    spans = [f["duration"]["nanoseconds"] for f in meta["files"]]
    assert len(spans) >= 5 and max(spans) < 2 * 86400 * 10**9
    assert read_bag_passes(tmp_path / "d").equals(part)


def test_sample_bag_regenerates_bit_for_bit(tmp_path: Path):
    out = tmp_path / "sample"
    r = run_cmd("rail-monitor", "simulate", "--out", str(out))
    assert r.returncode == 0, r.stderr
    for name in ("metadata.yaml", "sample_0.mcap"):
        assert (out / name).read_bytes() == (SAMPLE / name).read_bytes(), name
    assert (SAMPLE / "sample_0.mcap").stat().st_size < 5 * 2**20


def _bad_bags(tmp: Path, sample: Path) -> dict[str, Path]:
    mcap = sample / "sample_0.mcap"
    bags = {}
    empty = tmp / "empty.mcap"
    empty.write_bytes(b"")
    bags["empty file"] = empty
    magic = tmp / "magic.mcap"
    magic.write_bytes(b"NOTMCAP!" + mcap.read_bytes()[8:])
    bags["wrong magic"] = magic
    trunc = tmp / "trunc"
    trunc.mkdir()
    shutil.copy(sample / "metadata.yaml", trunc / "metadata.yaml")
    (trunc / "sample_0.mcap").write_bytes(mcap.read_bytes()[: mcap.stat().st_size // 2])
    bags["truncated"] = trunc
    bags["missing"] = tmp / "nope"
    garbage = tmp / "garbage"
    garbage.mkdir()
    (garbage / "metadata.yaml").write_text("rosbag2_bagfile_information: [oops\n")
    bags["bad metadata"] = garbage
    with McapBagWriter(tmp / "wrong_type") as w:
        w.add_topic("/train_pass", "diagnostic_msgs/msg/DiagnosticArray")
    bags["train_pass of the wrong type"] = tmp / "wrong_type"
    # bare MCAP files written record by record (the bag writer refuses these)
    bags["unknown message type"] = _raw_mcap(tmp / "unknown.mcap", "/axles", ("acme_msgs/msg/Axle", b"float64 x"))
    bags["missing schema"] = _raw_mcap(tmp / "schemaless.mcap", "/train_pass", None)
    bags["TrainPass of another definition"] = _raw_mcap(tmp / "otherdef.mcap", "/train_pass",
                                                        (TRAIN_PASS, b"float64 x"))
    return bags


def _raw_mcap(path: Path, topic: str, schema: tuple[str, bytes] | None) -> Path:
    from mcap.writer import Writer

    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile="ros2", library="test")
        sid = w.register_schema(name=schema[0], encoding="ros2msg", data=schema[1]) if schema else 0
        ch = w.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)
        w.add_message(channel_id=ch, log_time=1, data=b"\x00\x01\x00\x00" + bytes(40), publish_time=1)
        w.finish()
    return path


def _bad_csvs(tmp: Path) -> dict[str, Path]:
    header = "time_utc,train_id,vehicle_class,vehicle_count,speed_mps,angle_of_attack_rad,friction_state\n"
    row = "2026-09-01T05:00:00Z,T1,emu,3,19.0,0.005,dry\n"
    files = {"csv in an unknown unit": (header.replace("speed_mps", "speed_mph") + row).encode(),
             "csv in Latin-1": (header + row.replace("T1", "Zug\xe41")).encode("latin-1"),
             "csv in UTF-16": (header + row).encode("utf-16"),
             "csv with a row short": (header + row.replace(",dry", "")).encode()}
    out = {}
    for i, (what, data) in enumerate(files.items()):
        out[what] = tmp / f"bad{i}.csv"
        out[what].write_bytes(data)
    return out


def test_bad_bags_raise_one_line_input_errors(tmp_path: Path):
    for what, path in _bad_bags(tmp_path, SAMPLE).items():
        with pytest.raises(InputError) as err:
            read_bag_passes(path)
        assert str(path) in str(err.value) and "\n" not in str(err.value), what


def test_wrong_topic_type_is_named(tmp_path: Path):
    with McapBagWriter(tmp_path / "diag") as w:
        w.add_topic("/train_pass", "diagnostic_msgs/msg/DiagnosticArray")
    with pytest.raises(InputError, match="no rail_msgs/msg/TrainPass topic in the bag; it has /train_pass"):
        read_bag_passes(tmp_path / "diag")
    with pytest.raises(InputError, match="is diagnostic_msgs/msg/DiagnosticArray, not rail_msgs/msg/TrainPass"):
        read_bag_passes(tmp_path / "diag", topic="/train_pass")


def _in_process(argv: list[str], capsys) -> subprocess.CompletedProcess:
    """rail-monitor run in this process (the console script is sys.exit(main()): the same code, without
    a process start per command); an exception escaping it fails the test."""
    from rail_monitor.cli import main

    code = main(argv)
    out = capsys.readouterr()
    return subprocess.CompletedProcess(argv, code, out.out, out.err)


def test_cli_on_bad_bags_one_line_nonzero_no_traceback(tmp_path: Path, tally, capsys):
    bad = {**_bad_bags(tmp_path, SAMPLE), **_bad_csvs(tmp_path)}
    for what, path in bad.items():
        for cmd in (["rail-monitor", "info", str(path)], ["pass_replayer", "--ros-args", "-p", f"source:={path}"],
                    ["rail-monitor", "batch", str(path), "--output", str(tmp_path / "b"), "--no-report"]):
            r = run_cmd(*cmd, timeout=60) if cmd[0] == "pass_replayer" else _in_process(cmd[1:], capsys)
            assert "Traceback" not in r.stderr, (what, r.stderr)
            if cmd[1] == "info" and r.returncode == 0:  # info summarises a readable bag without passes
                assert "TrainPass" not in r.stdout and what.startswith(("train_pass", "unknown", "missing")), what
                continue
            assert r.returncode != 0, (what, cmd)
            errors = [line for line in r.stderr.splitlines() if "error:" in line]
            assert len(errors) == 1 and str(path) in errors[0], (what, r.stderr)
    tally("bad files", f"{len(bad)} unusable histories ({', '.join(bad)}), each through info, pass_replayer "
          "and batch", "one-line error naming the file, non-zero exit, no traceback (info lists the topics of "
          "a readable bag without passes)", "-")


def test_salvage_reads_every_complete_chunk_of_a_cut_file(tmp_path: Path, sample_passes):
    data = pass_cdr(sample_passes.take(slice(0, 3000)), "s")
    with McapBagWriter(tmp_path / "c", chunk_size=8192) as w:
        w.add_topic("/train_pass", TRAIN_PASS)
        for i, d in enumerate(data):
            w.write("/train_pass", d, 10**18 + i)
    whole = (tmp_path / "c" / "c_0.mcap").read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole[: int(len(whole) * 0.6)])
    got = list(salvage_mcap(cut))
    assert 0.4 * 3000 < len(got) < 0.75 * 3000
    assert [m.data for m in got] == data[: len(got)]  # a prefix, in order, intact


def test_killed_writer_process_leaves_readable_chunks(tmp_path: Path):
    # A child process writes through McapBagWriter and is SIGKILLed mid-stream.
    script = tmp_path / "w.py"
    script.write_text(
        "import sys, time\n"
        "from rail_monitor.bagio.mcap_bag import McapBagWriter\n"
        "w = McapBagWriter(sys.argv[1], chunk_size=2048)\n"
        "w.add_topic('/x', 'rail_msgs/msg/TrainPass')\n"
        "blob = open(sys.argv[2], 'rb').read()\n"
        "i = 0\n"
        "while True:\n"
        "    w.write('/x', blob, 10**18 + i); i += 1\n"
        "    if i == 2000: print('ready', flush=True)\n"
    )
    blob = tmp_path / "blob"
    blob.write_bytes(pass_cdr(read_bag_passes(SAMPLE).take(slice(0, 1)), "s")[0])
    env = dict(os.environ)
    p = subprocess.Popen([shutil.which("python") or "python", str(script), str(tmp_path / "k"), str(blob)],
                         stdout=subprocess.PIPE, text=True, env=env, cwd=TOP)
    assert p.stdout.readline().strip() == "ready"
    p.kill()
    p.wait(timeout=10)
    got = list(salvage_mcap(tmp_path / "k" / "k_0.mcap"))
    assert len(got) >= 1900  # all but the open chunk (about 2048 bytes of messages)
    assert all(m.data == blob.read_bytes() for m in got)


def test_header_stamp_read_from_cdr(sample_passes):
    from rail_monitor.codec.typestore import header_stamp_ns, starts_with_header

    assert starts_with_header(TRAIN_PASS) and starts_with_header("diagnostic_msgs/msg/DiagnosticArray")
    assert not starts_with_header("rosgraph_msgs/msg/Clock")
    data = pass_cdr(sample_passes.take(slice(0, 20)), "s")
    assert [header_stamp_ns(d) for d in data] == list(sample_passes.stamp_ns[:20])
