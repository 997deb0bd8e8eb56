"""Tests of rail_monitor.corrugation."""
