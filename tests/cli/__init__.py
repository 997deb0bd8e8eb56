"""Tests of rail_monitor.cli."""
