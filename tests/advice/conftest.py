"""The corrugation tests' fixtures (the sample site, its growth tables, the sample passes)."""

from corrugation.conftest import sample, site_, tables  # noqa: F401  (fixtures)
