"""Batch mode: a site's engine fed a whole history in chunks (run), recorded as the live graph is
recorded (bag), and many sites on a Dask cluster (sites). No rclpy, no generated messages."""
