"""Corrugation at a site: the state per wavelength band, its forecast, surveys, advice, checkpoints.

- :mod:`.config`: the site's corrugation parameters.
- :mod:`.growth`: per-axle-pass growth tables per vehicle class and friction state.
- :mod:`.history`: the kept passes.
- :mod:`.estimator`: the state, advanced by passes (one or many, the same functions live and batch).
- :mod:`.forecast`: time to the intervention threshold.
- :mod:`.records`: forecasts, snapshots, trajectories, evaluations, advice.
- :mod:`.surveys`: measured surveys (K_b re-fit) and grinding.
- :mod:`.advice`: what-if speed distributions and the speed advice.
- :mod:`.checkpoint`: atomic checkpoints with fallback.
- :mod:`.whatif`: what ``rail-monitor predict corrugation`` computes.

The model is wear-type corrugation growth as presented in the seminar paper of the University of
Queensland Rail Mechanics Group (see docs/models.md for the equations as implemented here).

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
   acoustic phenomena", seminar paper (section 2.1, eqs. 1-2).
.. [2] S. L. Grassie, M. J. Saxon and J. D. Smith, "Measurement of longitudinal rail irregularities
   and criteria for acceptable grinding", Journal of Sound and Vibration 227(5) (1999) 949-964.
"""
