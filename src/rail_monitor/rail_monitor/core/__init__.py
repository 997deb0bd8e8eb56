"""What every layer shares: the site, the pass table and its validation, parameter specs, time, errors.

- :mod:`~rail_monitor.core.errors`: the one-line errors front ends print without a traceback.
- :mod:`~rail_monitor.core.params`: :class:`~rail_monitor.core.params.ParamSpec`, the single
  source of a parameter's name, default, unit and range, and the checks applied to values.
- :mod:`~rail_monitor.core.site`: the site (curve, wheel-rail contact, track, rolling stock).
- :mod:`~rail_monitor.core.passes`: the columnar pass table and the one rule set that accepts
  or rejects a pass.
- :mod:`~rail_monitor.core.node_params`: the parameters of the graph's nodes that belong to no
  model (pass sources, recorder, the one-process graph).
- :mod:`~rail_monitor.core.timeutil`: conversions between ISO 8601, ns and (sec, nanosec).
"""
