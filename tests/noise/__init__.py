"""Tests of rail_monitor.noise."""
