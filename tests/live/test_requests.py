"""The rate requester's command protocol, driven with real MAVLink bytes and a stepped clock."""

from __future__ import annotations

from pymavlink.dialects.v20 import ardupilotmega as mavlink

from gcs_sysid.live.requests import ACK_TIMEOUT_S, ACK_TRIES, RateRequester

VEHICLE = (1, 1)


class _Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def _requester(rates):
    sent: list[bytes] = []
    clock = _Clock()
    rq = RateRequester(mavlink.MAVLink(None, srcSystem=255, srcComponent=191), sent.append, dict(rates), clock)
    rq.target = VEHICLE
    return rq, sent, clock


def _decode(sent):
    parser = mavlink.MAVLink(None)
    return [parser.decode(bytearray(b)) for b in sent]


def _ack(result, src=VEHICLE):
    """A COMMAND_ACK from ``src`` as the listener's link would decode it."""
    enc = mavlink.MAVLink(None, srcSystem=src[0], srcComponent=src[1])
    return mavlink.MAVLink(None).decode(bytearray(enc.command_ack_encode(511, result).pack(enc)))


def test_an_answer_held_past_two_timeouts_is_still_taken():
    """A router on a loaded machine held the answer 2.6 s (seen behind MAVProxy): three tries wait for it."""
    rq, sent, clock = _requester({"ATTITUDE": 50.0})
    for t in (0.0, 1.05 * ACK_TIMEOUT_S, 2.1 * ACK_TIMEOUT_S):    # no answer yet: retried, confirmation counted up
        clock.t = t
        rq.tick(dict)
    clock.t = 2.6 * ACK_TIMEOUT_S
    rq.handle(_ack(0))
    msgs = _decode(sent)
    assert [m.get_type() for m in msgs] == ["COMMAND_LONG"] * 3
    assert [m.confirmation for m in msgs] == [0, 1, 2]
    assert {(m.command, m.param1, m.param2) for m in msgs} == {(511, mavlink.MAVLINK_MSG_ID_ATTITUDE, 1e6 / 50.0)}
    assert rq.result == {"ATTITUDE": "accepted"}


def test_an_unanswered_request_falls_back_to_its_stream_group_and_the_next_is_asked():
    rq, sent, clock = _requester({"ATTITUDE": 50.0, "WIND": 2.0})
    rq.tick(dict)
    for k in range(1, ACK_TRIES + 1):
        clock.t = k * (ACK_TIMEOUT_S + 0.05)
        rq.tick(dict)
    msgs = _decode(sent)
    assert rq.result == {"ATTITUDE": "no answer"}
    assert [m.get_type() for m in msgs] == ["COMMAND_LONG"] * ACK_TRIES + ["REQUEST_DATA_STREAM", "COMMAND_LONG"]
    assert (msgs[ACK_TRIES].req_stream_id, msgs[ACK_TRIES].req_message_rate) == (10, 50)   # ATTITUDE's group
    assert msgs[-1].param1 == mavlink.MAVLINK_MSG_ID_WIND and msgs[-1].confirmation == 0
    rq.handle(_ack(0, src=(1, 190)))                   # another component's answer is not the vehicle's
    assert "WIND" not in rq.result
    rq.handle(_ack(2))
    assert rq.result["WIND"] == "denied"
    assert _decode(sent)[-1].get_type() == "REQUEST_DATA_STREAM"
