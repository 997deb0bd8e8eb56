"""A site's engine: the site parsed once (site_config), the corrugation state advanced by its
inputs in stamp order, the same code live and in batch (corrugation_site: the state with its
surveys, grinding and indirect windows), and that state on disk (checkpoint). No rclpy."""
