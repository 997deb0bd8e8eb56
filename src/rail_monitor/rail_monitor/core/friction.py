"""Friction states of a pass: the TrainPass.FRICTION_* codes and their names in CSV files and site
parameters."""

FRICTION_UNSET, FRICTION_DRY, FRICTION_WET, FRICTION_MODIFIER, FRICTION_CONTAMINATED = range(5)
FRICTION_NAMES: dict[int, str] = {
    FRICTION_DRY: "dry",
    FRICTION_WET: "wet",
    FRICTION_MODIFIER: "friction_modifier",
    FRICTION_CONTAMINATED: "contaminated",
}
FRICTION_BY_NAME: dict[str, int] = {v: k for k, v in FRICTION_NAMES.items()}
