"""noise_station: a wayside noise station that hears each pass from its recorded audio.

Subscribes ``train_pass``; for each accepted pass it waits (at most ``station.audio_wait_s`` of
wall time) for the pass's WAV in ``station.audio_folder`` (rail_monitor.station.pass_audio:
named by the pass's stamp and train id, starting ``station.lead_s`` before its stamp), reduces it
to its ISO 3095 levels, 1/3-octave bands and squeal, and publishes it on ``noise/measured``
(rail_msgs/MeasuredPassNoise, the pass's stamp and train id), where the estimator's indirect
roughness and the alert manager's residuals take it, and the recorder keeps it (a replay of the
bag sends it again). Audio travels as files, not messages: Jazzy's wheels carry no standard audio
message, and a station's recorder leaves files.

With ``station.archive_folder`` it keeps the audio of the passes worth hearing within
``station.archive_budget_mb`` (rail_monitor.station.archive): every squealing pass, the
``station.loudest_per_day`` loudest of each day, and the wheel-defect suspects that
``noise/residual`` names (``alerts.residual_model``'s residual at least
``alerts.wheel_defect_raise_db`` above the baseline). What it removes or cannot keep is logged
and counted on /diagnostics.
"""

from __future__ import annotations

import sys
import time
from collections import Counter, OrderedDict
from pathlib import Path
from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus

from rail_monitor.alerts.config import ALERT_SPECS
from rail_monitor.core.errors import ConfigError, RailMonitorError
from rail_monitor.core.params import values_of
from rail_monitor.core.passes import PassTable
from rail_monitor.messages.fields import PassHead, measured_pass_noise_fields, time_ns
from rail_monitor.nodes.base import declare, subscribe_batched, wall_timer
from rail_monitor.nodes.convert import to_cdr
from rail_monitor.nodes.pass_consumer import PassConsumerNode
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.qos import STREAM_QOS, STREAM_SUB_QOS
from rail_monitor.station.archive import AudioArchive
from rail_monitor.station.config import STATION_SPECS, StationConfig
from rail_monitor.station.pass_audio import audio_name, hear_pass, measurement, sensitivity
from rail_msgs.msg import MeasuredPassNoise, NoiseResidual

SUSPECT_SPECS = tuple(s for s in ALERT_SPECS if s.name in ("residual_model", "wheel_defect_raise_db"))
SETTLE_S = 1.0          # a file younger than this may still be being written: looked at again later
LOOK_PERIOD_S = 0.5     # how often the folder is looked at for the audio of waiting passes
HEARD_KEPT = 10_000     # heard passes remembered for a later wheel-defect verdict
MIB = 1 << 20


class NoiseStation(PassConsumerNode):
    EXECUTABLE = "noise_station"
    PARAMETERS = (*PassConsumerNode.PARAMETERS, ("station.", STATION_SPECS), ("alerts.", SUSPECT_SPECS))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__("noise_station", **kwargs)
        self.cfg: StationConfig = values_of(StationConfig, declare(self, STATION_SPECS, prefix="station."))
        suspect = declare(self, SUSPECT_SPECS, prefix="alerts.")
        self.residual_model, self.suspect_db = suspect["residual_model"], suspect["wheel_defect_raise_db"]
        if not self.cfg.audio_folder:
            raise ConfigError("station.audio_folder is empty: name the folder the station's recorder leaves "
                              "each pass's WAV in")
        self.folder = Path(self.cfg.audio_folder)
        if not self.folder.is_dir():
            raise ConfigError(f"station.audio_folder {self.folder}: no such folder")
        if self.cfg.sensitivity_pa_per_unit == 0.0 and not self.cfg.calibration_file:
            raise ConfigError("station.sensitivity_pa_per_unit is 0 and station.calibration_file is empty: give the "
                              "recordings' pascals per unit, or a calibrator's recording")
        self.scale = sensitivity(self.cfg.sensitivity_pa_per_unit, self.cfg.calibration_file,
                                 self.cfg.calibration_db, self.cfg.channel)
        self.archive = AudioArchive(self.cfg.archive_folder, int(self.cfg.archive_budget_mb * MIB),
                                    self.cfg.loudest_per_day) if self.cfg.archive_folder else None
        self.waiting: OrderedDict[tuple[int, str], tuple[float, float]] = OrderedDict()  # key -> (Tp [s], deadline)
        self.heard: OrderedDict[tuple[int, str], float] = OrderedDict()  # key -> LpAFmax, for suspects
        self.counts: Counter[str] = Counter()
        self.pub = self.create_publisher(MeasuredPassNoise, "noise/measured", STREAM_QOS)
        subscribe_batched(self, NoiseResidual, "noise/residual", self._on_residuals, STREAM_SUB_QOS, self.max_batch)
        wall_timer(self, LOOK_PERIOD_S, self.look)
        self.listen()

    def key_parameters(self) -> dict[str, Any]:
        return {"audio_folder": str(self.folder), "sensitivity_pa_per_unit": f"{self.scale:.6g}",
                "archive": self.cfg.archive_folder or "none"}

    def on_passes(self, table: PassTable, heads: list[PassHead]) -> None:
        deadline = time.monotonic() + self.cfg.audio_wait_s
        tp = table.train_length_m / table.speed_mps
        for h, t in zip(heads, tp.tolist(), strict=True):
            self.waiting[(h.stamp_ns, h.train_id)] = (t, deadline)
        self.look()

    def look(self) -> None:
        """Hear every waiting pass whose audio is there; give up on those past their wait."""
        now, wall = time.monotonic(), time.time()
        for key, (tp, deadline) in list(self.waiting.items()):
            path = self.folder / audio_name(*key)
            try:
                ready = wall - path.stat().st_mtime >= SETTLE_S
            except OSError:
                ready = False
            if ready:
                del self.waiting[key]
                self._hear(key, path, tp)
            elif now >= deadline:
                del self.waiting[key]
                self.counts["not heard: no audio within audio_wait_s"] += 1
                self.get_logger().warning(f"pass {key[1]!r}: no {path.name} in {self.folder} within "
                                          f"{self.cfg.audio_wait_s:g} s", throttle_duration_sec=self.log_throttle_s)
        self._report_archive()

    def _hear(self, key: tuple[int, str], path: Path, tp: float) -> None:
        try:
            heard = hear_pass(path, self.scale, self.cfg, tp)
        except RailMonitorError as exc:
            self.counts["not heard: audio unusable"] += 1
            self.get_logger().warning(str(exc), throttle_duration_sec=self.log_throttle_s)
            return
        m = measurement(key[0], key[1], heard, self.cfg)
        self.sent.send(self.pub, to_cdr(MeasuredPassNoise, measured_pass_noise_fields(m, self.site.site_id)))
        self.counts["heard"] += 1
        self.counts["squealing"] += m.squeal_detected
        self.counts["flanging"] += m.flanging_detected
        self.heard[key] = m.lpafmax_dba
        while len(self.heard) > HEARD_KEPT:
            self.heard.popitem(last=False)
        if self.archive is not None:
            self._archived(lambda: self.archive.offer(path, key[0], key[1], m.lpafmax_dba, m.squeal_detected))

    def _on_residuals(self, msgs: list[NoiseResidual]) -> None:
        if self.archive is None:
            return
        for r in msgs:
            key = (time_ns(r.header.stamp), r.train_id)
            if r.model == self.residual_model and r.excess_mid_db >= self.suspect_db and key in self.heard:
                path = self.folder / audio_name(*key)
                self._archived(lambda p=path, k=key: self.archive.suspect(p, k[0], k[1], self.heard[k]))

    def _archived(self, step) -> None:
        """An archive step; a failing disk is counted and logged, and the station goes on hearing."""
        try:
            step()
        except OSError as exc:
            self.counts["archive write failed"] += 1
            self.get_logger().error(f"audio archive {self.cfg.archive_folder}: {exc}",
                                    throttle_duration_sec=self.log_throttle_s)

    def _report_archive(self) -> None:
        if self.archive is not None:
            for note in self.archive.take_notes():
                self.get_logger().warning(note, throttle_duration_sec=self.log_throttle_s)

    def diagnostic_values(self) -> dict[str, Any]:
        values = {**super().diagnostic_values(), "pending": len(self.waiting), **self.counts}
        if self.archive is not None:
            values.update({"archive files": len(self.archive.kept),
                           "archive used MiB": f"{self.archive.used_bytes / MIB:.1f}",
                           **{f"archive {why}": n for why, n in sorted(self.archive.counts.items())}})
        return values

    def _level(self) -> tuple[int, str]:
        level, message = super()._level()
        if self.counts["archive write failed"] and level == DiagnosticStatus.OK:
            return DiagnosticStatus.ERROR, "the audio archive cannot be written"
        return level, message


def main(args: list[str] | None = None) -> int:
    return run_node(NoiseStation, args)


if __name__ == "__main__":
    sys.exit(main())
