"""Reading and writing pass histories and recordings: rosbag2 bags (MCAP, sqlite3) and CSV."""
