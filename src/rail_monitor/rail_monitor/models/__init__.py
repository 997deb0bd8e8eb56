"""Pure physics of the wayside monitor: vectorised numpy/scipy functions, SI units, no rclpy.

One module per piece of physics or per standard:

- :mod:`hertz`: elliptical Hertz contact (semi-axes, pressure, approach, contact stiffness).
- :mod:`kalker`: Kalker's linear creep coefficients (Kalker 1990, Table E.3).
- :mod:`squeal`: wheel squeal on a falling creep curve: stability, limit-cycle amplitude,
  time-domain check, radiated level.
- :mod:`iec61672`: frequency weighting A (IEC 61672-1).
"""
