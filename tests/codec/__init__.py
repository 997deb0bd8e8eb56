"""Tests of rail_monitor.codec."""
