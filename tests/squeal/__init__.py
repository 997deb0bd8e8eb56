"""Tests of rail_monitor.squeal."""
