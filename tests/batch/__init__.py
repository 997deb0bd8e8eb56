"""Tests of rail_monitor.batch."""
