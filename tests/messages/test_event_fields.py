"""The site's events as message fields (rail_monitor.messages.event_fields): a friction-modifier
applicator's start and stop through rosbags' CDR and rclpy and back, and the ones refused."""

from __future__ import annotations

from rclpy.serialization import deserialize_message

from rail_monitor.codec.cdr import message_view, serialize
from rail_monitor.codec.typestore import FRICTION_APPLICATOR
from rail_monitor.core.friction import ACTION_START, ACTION_STOP, MAX_PRODUCT_CHARS, ApplicatorEvent, applicator_refusal
from rail_monitor.messages.event_fields import applicator_from_msg, friction_applicator_fields
from rail_msgs.msg import FrictionApplicator


def test_an_applicator_event_survives_both_serialisers():
    """A start with its product, written by rosbags' CDR: rclpy decodes the same fields (its
    ACTION_* constants the module's), and both decodings read back as the event."""
    event = ApplicatorEvent(1_790_000_000_123_456_789, ACTION_START, "Keystone K-Tracker")
    data = serialize(FRICTION_APPLICATOR, friction_applicator_fields(event, "curve_250"))
    msg = deserialize_message(data, FrictionApplicator)
    assert (msg.action, msg.product, msg.header.frame_id) == (FrictionApplicator.ACTION_START, event.product,
                                                              "curve_250")
    assert (FrictionApplicator.ACTION_START, FrictionApplicator.ACTION_STOP) == (ACTION_START, ACTION_STOP)
    assert applicator_from_msg(msg) == event == applicator_from_msg(message_view(FRICTION_APPLICATOR, data))


def test_an_event_that_cannot_be_one_is_refused_with_its_reason():
    assert applicator_refusal(ApplicatorEvent(10**18, ACTION_STOP)) == ""
    assert applicator_refusal(ApplicatorEvent(-1, ACTION_START)) == "stamp before 1970"
    assert applicator_refusal(ApplicatorEvent(10**18, 7)) == "action 7 is not start (1) or stop (2)"
    assert "longer than" in applicator_refusal(ApplicatorEvent(10**18, ACTION_START, "x" * (MAX_PRODUCT_CHARS + 1)))
