"""Simulated inputs with a known truth: traffic (simulator), a noise station's measurements
(measurements) and roughness surveys (surveys) of a rail whose K_b is known. No rclpy."""
