"""Tests of rail_monitor.report."""
