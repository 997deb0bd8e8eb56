"""The noise station's cost: noise_station in a process of its own hearing passes of 10 s of audio
at 48 kHz (a rolling-noise record with a squeal-like tone), its CPU per pass heard and idle, and
what that makes of issue 54's duty of 100 passes an hour (target: at most 5 % of a core).

The passes come faster than an hour's 100 (one a second) so that the run is short; the CPU per pass
is the process's CPU over the run less its idle rate, over the passes heard.

Run: ros2_ws/run python -m bench.station [--passes 20]
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.io import wavfile

import bench  # noqa: F401  (one maths thread, a DDS domain of the run's own)
from bench.live import _spawn, cpu_s
from bench.spun_node import SpunNode
from bench.timing import header, parser

FS, RECORD_S, LEAD_S, TP_S = 48_000, 10.0, 2.0, 4.0
PER_HOUR = 100


class _Probe(SpunNode):
    """Publishes TrainPass and counts the MeasuredPassNoise that come back."""

    def __init__(self) -> None:
        from rail_monitor.nodes.convert import TOPICS
        from rail_monitor.nodes.qos import STREAM_SUB_QOS
        from rail_msgs.msg import MeasuredPassNoise

        super().__init__("bench_station_probe")
        cls, qos = TOPICS["train_pass"]
        self.pub = self.node.create_publisher(cls, "train_pass", qos)
        self.heard = 0
        self.node.create_subscription(MeasuredPassNoise, "noise/measured", self._on_heard, STREAM_SUB_QOS)
        self.start()

    def _on_heard(self, msg: object) -> None:
        with self.lock:
            self.heard += 1


def costs(site: str, passes: int = 20) -> dict[str, float]:
    from rail_monitor.core.passes import FRICTION_DRY, PassTable, with_class_defaults
    from rail_monitor.core.site import site_from_values
    from rail_monitor.messages.fields import train_pass_fields
    from rail_monitor.nodes.convert import TOPICS, to_msg
    from rail_monitor.site_file import load_parameter_file
    from rail_monitor.station.pass_audio import audio_name

    s = site_from_values(load_parameter_file(site))
    cls = s.vehicle(next(iter(s.vehicles)))
    rng = np.random.default_rng(54)
    t = np.arange(round(RECORD_S * FS)) / FS
    record = (rng.normal(0.0, 0.2, len(t)) + 0.5 * np.sin(2 * np.pi * 800.0 * t)).astype(np.float32)
    start = time.time_ns()
    stamps = [start + i * 10**9 for i in range(passes)]
    table = with_class_defaults(PassTable(
        stamp_ns=stamps, train_id=[f"S{i}" for i in range(passes)], vehicle_class=[cls.name] * passes,
        vehicle_count=[4] * passes, axle_count=[0] * passes, speed_mps=[cls.speed_mean_mps] * passes,
        angle_of_attack_rad=[0.0] * passes, wheel_load_n=[0.0] * passes, friction_state=[FRICTION_DRY] * passes,
        train_length_m=[TP_S * cls.speed_mean_mps] * passes), s)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for st, train in zip(stamps, table.train_id, strict=True):
            wavfile.write(folder / audio_name(st, str(train)), FS, record)
        time.sleep(1.1)  # the station takes a file once it is a second old (one being written is not)
        probe = _Probe()
        proc = _spawn("noise_station", site, f"station.audio_folder:={folder}", f"station.lead_s:={LEAD_S}",
                      "station.sensitivity_pa_per_unit:=1.0")
        try:
            while probe.pub.get_subscription_count() < 1 and proc.poll() is None:
                time.sleep(0.05)
            time.sleep(2.0)                              # start-up done
            c0, w0 = cpu_s(proc.pid), time.monotonic()
            time.sleep(5.0)
            idle = (cpu_s(proc.pid) - c0) / (time.monotonic() - w0)
            c1, w1 = cpu_s(proc.pid), time.monotonic()
            cls_msg = TOPICS["train_pass"][0]
            for i in range(passes):
                probe.pub.publish(to_msg(cls_msg, train_pass_fields(table.row(i), "curve_250")))
                time.sleep(1.0)
            deadline = time.monotonic() + 60.0
            while probe.heard < passes and time.monotonic() < deadline:
                time.sleep(0.05)
            busy_cpu, busy_wall = cpu_s(proc.pid) - c1, time.monotonic() - w1
        finally:
            proc.terminate()
            proc.wait(timeout=30)
            probe.close()
    per_pass = (busy_cpu - idle * busy_wall) / max(probe.heard, 1)
    return {"heard": probe.heard, "passes": passes, "idle_share": idle, "per_pass_s": per_pass,
            "duty_share": idle + PER_HOUR * per_pass / 3600.0}


def main() -> None:
    from rail_monitor.site_file import shipped_site_file

    ap = parser(__doc__)
    ap.add_argument("--passes", type=int, default=20)
    ns = ap.parse_args()
    header("station")
    c = costs(str(shipped_site_file()), ns.passes)
    print(f"heard {c['heard']} of {c['passes']} passes of {RECORD_S:g} s at 48 kHz: {c['per_pass_s'] * 1e3:.0f} ms "
          f"CPU per pass, idle {100 * c['idle_share']:.2f} % of a core; at {PER_HOUR} passes an hour "
          f"{100 * c['duty_share']:.2f} % of a core (target <= 5 %)")


if __name__ == "__main__":
    main()
