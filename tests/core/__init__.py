"""Tests of rail_monitor.core."""
