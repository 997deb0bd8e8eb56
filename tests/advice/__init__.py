"""Tests of rail_monitor.advice."""
