"""What-if questions asked of the models, as ``rail-monitor predict`` asks them: corrugation and its
advice, rolling noise of a train at speeds, squeal of a rig or site case, the indirect roughness of
a run, and their figures (plots). No rclpy."""
