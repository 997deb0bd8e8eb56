"""Friction states of a pass: the TrainPass.FRICTION_* codes and their names in CSV files and site
parameters; a friction-modifier applicator's start and stop (rail_msgs/FrictionApplicator)."""

from __future__ import annotations

from dataclasses import dataclass

FRICTION_UNSET, FRICTION_DRY, FRICTION_WET, FRICTION_MODIFIER, FRICTION_CONTAMINATED = range(5)
FRICTION_NAMES: dict[int, str] = {
    FRICTION_DRY: "dry",
    FRICTION_WET: "wet",
    FRICTION_MODIFIER: "friction_modifier",
    FRICTION_CONTAMINATED: "contaminated",
}
FRICTION_BY_NAME: dict[str, int] = {v: k for k, v in FRICTION_NAMES.items()}

ACTION_START, ACTION_STOP = 1, 2  # rail_msgs/FrictionApplicator.ACTION_*
ACTION_NAMES: dict[int, str] = {ACTION_START: "start", ACTION_STOP: "stop"}
MAX_PRODUCT_CHARS = 200


@dataclass(frozen=True)
class ApplicatorEvent:
    """A trackside friction-modifier applicator at the site started or stopped (stamp [ns])."""

    stamp_ns: int
    action: int        # ACTION_START or ACTION_STOP
    product: str = ""  # the modifier applied (free text)


def applicator_refusal(e: ApplicatorEvent) -> str:
    """Why an applicator event cannot be taken ('' if it can)."""
    if e.stamp_ns < 0:
        return "stamp before 1970"
    if e.action not in ACTION_NAMES:
        return f"action {e.action} is not start ({ACTION_START}) or stop ({ACTION_STOP})"
    if len(e.product) > MAX_PRODUCT_CHARS:
        return f"product longer than {MAX_PRODUCT_CHARS} characters"
    return ""
