"""A noise station that hears: a pass's recorded audio reduced to its measured pass-by and squeal
(:mod:`.pass_audio`), the station's parameters (:mod:`.config`), and the audio kept of the passes
worth hearing within a disk budget (:mod:`.archive`). No rclpy: the noise_station node and
``rail-monitor measure passby`` call these."""
