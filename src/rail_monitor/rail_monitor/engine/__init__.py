"""A site's engine: every state of one site, advanced by its inputs in stamp order, the same code
live and in batch (corrugation_site: the state with its surveys, grinding and indirect windows;
checkpoint: that state on disk). No rclpy."""
