"""Pure physics of the wayside monitor: vectorised numpy/scipy functions, SI units, no rclpy.

One module per piece of physics or per standard:

- :mod:`.hertz`: elliptical Hertz contact (semi-axes, pressure, approach, contact stiffness).
- :mod:`.kalker`: Kalker's linear creep coefficients (Kalker 1990, Table E.3).
- :mod:`.squeal`: wheel squeal on a falling creep curve: k3 conventions, stability, limit-cycle
  amplitude (closed form, and the energy balance over the whole curve), radiated level.
- :mod:`.squeal_ode`: direct time integration of the squeal ODE (the independent check).
- :mod:`.track`: vertical track receptance (Euler or Timoshenko rail on a two-layer support,
  continuous and discrete), wheel receptance, track decay rate.
- :mod:`.contact_filter`: the Hertzian contact filter of short-wavelength roughness.
- :mod:`.corrugation`: wear-type corrugation growth per wheel pass, wavelength bands, the
  grinding limits of Grassie et al. (1999), the full-sliding K_b.
- :mod:`.speed_plan`: the speed advice's linear programme (shares per class and speed band).
- :mod:`.cnossos`: the CNOSSOS-EU railway source model and its Appendix G tables.
- :mod:`.wheel_rail_noise`: the mechanics rolling-noise model (roughness to radiated power).
- :mod:`.radiation`: radiation efficiencies and radiated power.
- :mod:`.passby`: pass-by levels of a moving line source at a wayside receiver.
- :mod:`.levels`: level arithmetic, energy sums, A-weighted totals, octaves.
- :mod:`.iec61260`: one-third-octave bands (IEC 61260-1).
- :mod:`.iec61672`: frequency weighting A (IEC 61672-1).

The equations as implemented, their conventions and the known errors of the source paper are
in docs/models.md.
"""
