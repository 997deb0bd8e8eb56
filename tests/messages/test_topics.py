"""The graph's topic table (rail_monitor.messages.topics): QoS that lets no start-up order lose output."""

from __future__ import annotations

from rail_monitor.messages.topics import EVENT, GRAPH_TOPICS, OPTIONAL_TOPICS


def test_every_topic_but_the_survey_input_is_reliable_and_latched():
    """Each process of the graph discovers the others in its own time, and a recorder subscribes a
    topic only once it has seen its publisher. A volatile output published in that moment is lost
    to the bag (the indirect roughness was, once in three runs of the five-process comparison with
    batch). Only the survey input is volatile: its sender waits for its subscribers' acknowledgement,
    and a latched survey would greet every later subscriber (a restarted estimator) with an old one."""
    table = {**GRAPH_TOPICS, **OPTIONAL_TOPICS}
    assert all(q.reliable for _, q in table.values())
    assert {name for name, (_, q) in table.items() if not q.transient_local} == {"roughness_survey"}
    assert table["roughness_survey"][1] is EVENT
