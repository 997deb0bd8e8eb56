"""Batch mode without ROS (rail_monitor.app.batch): it imports and records a bag with rclpy and the
generated messages unavailable, and that bag decodes to what the rclpy path gives."""

from __future__ import annotations

import subprocess
import sys
import textwrap

from conftest import SITE_FILE, TOP

# Run in a fresh interpreter in which importing rclpy or the generated rail_msgs / diagnostic_msgs /
# builtin_interfaces Python packages fails, as on a machine without them.
_NO_ROS = textwrap.dedent("""
    import sys
    for name in ("rclpy", "rail_msgs", "builtin_interfaces", "std_msgs", "diagnostic_msgs", "rosgraph_msgs"):
        sys.modules[name] = None  # import raises ImportError
    import rail_monitor.app.batch as batch
    import rail_monitor.app.report
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.site_file import load_parameter_file
    values = load_parameter_file(sys.argv[1])
    result = batch.run_models(read_passes(sys.argv[2]), values)
    batch.write_bag(result, sys.argv[3], "curve_250")
    assert not any(m == "rclpy" or m.startswith(("rclpy.", "rail_msgs.")) for m in sys.modules if sys.modules[m])
    print(len(result.passes), len(result.trajectory))
""")


def test_batch_imports_and_records_without_rclpy_or_generated_messages(tmp_path):
    out = tmp_path / "bag"
    r = subprocess.run([sys.executable, "-c", _NO_ROS, str(SITE_FILE), str(TOP / "bags" / "example_passes.csv"),
                        str(out)], capture_output=True, text=True, timeout=120, cwd=TOP)
    assert r.returncode == 0, r.stderr[-2000:]
    passes, states = map(int, r.stdout.split())
    assert passes == 194 and states == 194
    assert (out / "metadata.yaml").exists()


def test_a_bag_written_without_rclpy_decodes_with_rclpy_to_the_same_messages(tmp_path, site_values):
    """Every message batch mode serialises (rosbags' CDR) decodes with rclpy's own deserialiser to the
    message the live graph would build from the same fields."""
    from mcap.reader import make_reader
    from rclpy.serialization import deserialize_message

    from rail_monitor.app.batch import run_models, write_bag
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.nodes.convert import TOPICS

    write_bag(run_models(read_passes(TOP / "bags" / "example_passes.csv"), site_values), tmp_path / "b", "site")
    seen = set()
    with open(next((tmp_path / "b").glob("*.mcap")), "rb") as fh:
        for _, channel, message in make_reader(fh).iter_messages():
            name = channel.topic.removeprefix("/site/")
            msg = deserialize_message(message.data, TOPICS[name][0])
            assert msg.header.stamp.sec > 0 and msg.header.frame_id == "curve_250"
            seen.add(name)
    assert seen == set(TOPICS)
