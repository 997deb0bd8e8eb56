"""Thin rclpy nodes: parameters, QoS, message conversion, calling the pure code."""
