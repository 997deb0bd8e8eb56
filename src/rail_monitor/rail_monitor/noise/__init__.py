"""Rolling noise at a site: parameters (:mod:`.config`), the per-pass prediction by CNOSSOS-EU and
by the mechanics model (:mod:`.predict`), and what ``rail-monitor predict noise`` computes
(:mod:`.whatif`).

References
----------
.. [1] Commission Directive (EU) 2015/996 establishing common noise assessment methods (CNOSSOS-EU),
   Annex II section 2.3, as amended by Commission Delegated Directive (EU) 2021/1226, Appendix G.
.. [2] D. J. Thompson, Railway Noise and Vibration: Mechanisms, Modelling and Means of Control,
   Elsevier, Oxford, 2009.
.. [3] Rail Mechanics Group, The University of Queensland, "A smorgasbord of railway dynamic and
   acoustic phenomena", seminar paper (section 2.2).
"""
