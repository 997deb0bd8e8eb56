"""Tests of rail_monitor.nodes."""
