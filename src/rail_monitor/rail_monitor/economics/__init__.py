"""Grinding economics: what a site's grinding costs, and a grinding programme for a network of sites."""
