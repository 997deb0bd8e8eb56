"""The mapping between the graph's messages and the models' records: every message as plain fields
and back (fields), the checks on the model outputs a node takes from another (output_columns),
and the graph's topic table with its QoS (topics)."""
