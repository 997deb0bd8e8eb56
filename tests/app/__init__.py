"""Tests of rail_monitor.app."""
