"""Tests of rail_monitor.models."""
