"""Measured pass-by noise in the loop: measurements checked and paired with their pass's
prediction, residuals per band and overall with their uncertainty, and the site's running baseline
that the wheel-defect and drift alerts compare with (no rclpy).

- :mod:`.records`: a measurement (rail_msgs/MeasuredPassNoise) and its checks.
- :mod:`.residuals`: the residual of one measurement against one model's prediction, and the
  tracker that pairs them and keeps the baseline.
- :mod:`.config`: the ``residual.*`` parameters.
"""
