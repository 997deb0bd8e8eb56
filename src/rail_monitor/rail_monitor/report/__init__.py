"""A recorded run read back (run_data), its console summary and report folder (summary, page,
tables, run_tables, plots) and its export as tables (export). No rclpy, no generated messages."""
