"""The CDR codec of the graph's messages without rclpy: the message definitions as rosbags reads
them (typestore), a type's CDR layout (cdr_layout), one message (cdr) and many of a type at once
as numpy columns (cdr_columns, cdr_from_columns)."""
