"""Tests of rail_monitor.bagio."""
