"""Tests of rail_monitor.messages."""
