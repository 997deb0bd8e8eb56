"""Tests of rail_monitor.engine."""
