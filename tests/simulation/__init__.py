"""Tests of rail_monitor.simulation."""
