"""Wheel squeal at a site: parameters (:mod:`.config`), the per-pass prediction (:mod:`.predict`)
and what ``rail-monitor predict squeal`` computes (:mod:`.whatif`).

The physics is :mod:`rail_monitor.models.squeal`: a single lateral wheel mode on a falling creep
curve, after the seminar paper of the University of Queensland Rail Mechanics Group (section 2.3,
eqs. 3-7), with the sign of its eq. (7) corrected (docs/models.md, "Wheel squeal").

References
----------
.. [1] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
   acoustic phenomena", seminar paper (sections 2.3 and 3).
.. [2] J. J. Kalker, Three-Dimensional Elastic Bodies in Rolling Contact, Kluwer, Dordrecht, 1990
   (Table E.3).
"""
