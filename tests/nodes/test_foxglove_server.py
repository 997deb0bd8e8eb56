"""The live view (issue 23): foxglove_server serves the running graph to Foxglove's own client.

The client is Foxglove's: @foxglove/ws-protocol's FoxgloveClient over ws, decoding each channel
with @foxglove/rosmsg and @foxglove/rosmsg2-serialization (tests/foxglove_client, versions pinned
by its package-lock.json, installed with npm on first use). The layout shipped for it is checked
against the message definitions.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import time

import pytest

from rail_monitor.codec.typestore import typestore
from rail_monitor.messages.topics import GRAPH_TOPICS

from conftest import SAMPLE, TOP, run_cmd, wait_until

CLIENT = TOP / "tests" / "foxglove_client"
LAYOUT = TOP / "src" / "rail_monitor" / "config" / "foxglove_layout.json"
NS = "/curve_250"


@pytest.fixture(scope="session")
def foxglove_client():
    if shutil.which("node") is None or shutil.which("npm") is None:
        pytest.skip("Node.js and npm are not installed: Foxglove's client cannot run")
    stamp = CLIENT / "node_modules" / ".lock_installed"
    lock = (CLIENT / "package-lock.json").read_text()
    if not stamp.exists() or stamp.read_text() != lock:
        r = subprocess.run(["npm", "ci", "--no-audit", "--no-fund"], cwd=CLIENT, capture_output=True, text=True,
                           timeout=600)
        assert r.returncode == 0, r.stderr[-2000:]
        stamp.write_text(lock)
    return CLIENT / "client.mjs"


def test_foxglove_client_receives_and_decodes_every_topic_of_the_running_graph(foxglove_client, tmp_path):
    log = tmp_path / "server.log"
    with open(log, "w") as err:
        server = subprocess.Popen(["foxglove_server", "--ros-args", "-r", f"__ns:={NS}", "-p", "port:=0",
                                   "-p", "use_sim_time:=true"], cwd=TOP, stderr=err, stdout=subprocess.DEVNULL)
    try:
        assert wait_until(lambda: "url=ws://" in log.read_text(), 30), log.read_text()[-2000:]
        url = re.search(r"url=(ws://\S+)", log.read_text()).group(1)
        client = subprocess.Popen(["node", str(foxglove_client), url, "300"], cwd=CLIENT, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True)
        time.sleep(2.0)  # connected before the graph starts
        # three train_pass subscribers: site_engine, the recorder and the live view
        r = run_cmd("rail-monitor", "monitor", str(SAMPLE), "--output", str(tmp_path / "bag"), "--end-offset-s",
                    str(5 * 86400.0), "--no-report", "--no-progress", "--ros-args", "-p", "wait_for_subscribers:=3",
                    timeout=180)
        assert r.returncode == 0, r.stderr[-2000:]
        time.sleep(2.0)  # the last messages on their way to the client
        client.send_signal(2)
        out, err = client.communicate(timeout=60)
    finally:
        server.send_signal(2)
        server.wait(timeout=30)
    assert client.returncode == 0, err[-2000:]
    got = json.loads(out.strip().splitlines()[-1])
    assert got["server"]["encodings"] == ["cdr"]
    topics = got["topics"]
    for name, (typename, _) in GRAPH_TOPICS.items():
        t = topics[f"{NS}/{name}"]
        assert t["schemaName"] == typename and t["schemaEncoding"] == "ros2msg" and t["encoding"] == "cdr"
        assert t["received"] >= 1 and t["decoded"] == t["received"] and t["errors"] == 0, (name, t)
    passes = topics[f"{NS}/train_pass"]
    assert passes["received"] == int(re.search(r"/curve_250/train_pass (\d+)", r.stdout).group(1))
    assert topics[f"{NS}/noise/rolling"]["received"] == 2 * passes["received"]  # both source models
    assert topics["/diagnostics"]["decoded"] >= 1 and "status" in topics["/diagnostics"]["last"]
    assert server.returncode == 0, log.read_text()[-2000:]


def _fields(typename: str) -> set[str]:
    """The field names of a message type (its installed definition)."""
    return {name for name, _ in typestore().fielddefs[typename][1]}


def test_the_layout_plots_fields_the_graph_publishes():
    layout = json.loads(LAYOUT.read_text())
    panels = layout["configById"]
    paths = [p["value"] for cfg in panels.values() for p in cfg.get("paths", [])]
    paths += [cfg[k] for cfg in panels.values() for k in ("topicPath", "topicToRender") if k in cfg]
    assert len(paths) >= 10
    topics = {f"{NS}/{name}": typename for name, (typename, _) in GRAPH_TOPICS.items()}
    topics["/diagnostics"] = "diagnostic_msgs/msg/DiagnosticArray"
    for path in paths:
        m = re.match(r"^(/[\w/]+?)(?:\{[^}]*\})?(?:\.(\w+)(?:\[\d+\])?)?$", path)
        assert m, path
        topic, field = m.groups()
        assert topic in topics, path
        if field:
            assert field in _fields(topics[topic]), path
    # every panel the layout tree names is configured
    names = re.findall(r'"(\w+![\w-]+)"', json.dumps(layout["layout"]))
    assert set(names) == set(panels)
