"""Tests of rail_monitor.alerts."""
