"""An MES team's test suite against motiond in virtual time, through the Python client that
openapi-python-client generates (nothing hand-written in between): a 60 s machine sequence —
homing, moves, a gear, a drive fault and its reset — that runs in a fraction of its machine
time and asserts exact positions, because the clock only runs when the test advances it.

    pytest tests/client/test_virtual_time.py

with the generated package `motiond_client` on PYTHONPATH and MOTIOND_BIN naming the binary
(tests/client/check.py runs it so).
"""

import os
import re
import subprocess
import threading
import time

import pytest

from motiond_client import Client
from motiond_client.api.axes import axis_status
from motiond_client.api.clock import advance, get_clock
from motiond_client.api.commands import gear_in, gear_out, home, move_absolute, power, reset
from motiond_client.api.simulation import inject_fault
from motiond_client.models import (
    AdvanceBody,
    Advanced,
    ClockState,
    CommandResource,
    CommandState,
    EmptyBody,
    GearInBody,
    HomeBody,
    MoveBody,
    PowerBody,
    SimFaultType0,
    SimFaultType0Kind,
    SimFaultType5,
    SimFaultType5Kind,
    StatusResource,
    UntilBody,
)


@pytest.fixture(scope="module")
def client():
    """motiond in virtual time on a fresh in-memory database, and a client of it."""
    p = subprocess.Popen(
        [os.environ["MOTIOND_BIN"], "serve", "--clock", "virtual", "--db", ":memory:",
         "--listen", "127.0.0.1:0", "--control-lease", "false"],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=dict(os.environ, NO_COLOR="1"),
    )
    addr: list[str] = []
    started = threading.Event()

    def read() -> None:
        for line in p.stdout:
            m = re.search(r"listening on (http://\S+)", line)
            if m and not addr:
                addr.append(m.group(1))
                started.set()
        started.set()

    threading.Thread(target=read, daemon=True).start()
    assert started.wait(60) and addr, "motiond did not start"
    with Client(base_url=addr[0], headers={"X-Client-Id": "mes-test"}, timeout=30.0) as c:
        yield c
    p.terminate()
    p.wait(10)


def accepted(r: object) -> CommandResource:
    assert isinstance(r, CommandResource), f"refused: {r}"
    return r


def run_until(client: Client, command: CommandResource, max_seconds: float = 60.0) -> CommandResource:
    """Runs the clock to exactly the cycle where the command reaches its block's milestone."""
    a = advance.sync(client=client, body=AdvanceBody(until=UntilBody(command=command.id), max_seconds=max_seconds))
    assert isinstance(a, Advanced), a
    assert a.until.reached, f"{command.command} did not get there: {a.until.command.state}"
    return a.until.command


def run_for(client: Client, seconds: float) -> Advanced:
    a = advance.sync(client=client, body=AdvanceBody(seconds=seconds))
    assert isinstance(a, Advanced), a
    return a


def status(client: Client, axis: str):
    s = axis_status.sync(axis=axis, client=client)
    assert isinstance(s, StatusResource), s
    return s.status


def test_a_60_s_machine_sequence_in_virtual_time(client: Client) -> None:
    wall = time.monotonic()
    c = get_clock.sync(client=client)
    assert isinstance(c, ClockState) and c.mode == "virtual" and c.cycle == 0, c

    for axis in ("x", "y"):
        run_until(client, accepted(power.sync(axis=axis, client=client, body=PowerBody())))
    done = run_until(client, accepted(home.sync(axis="x", client=client, body=HomeBody())))
    assert done.state == CommandState.DONE
    assert status(client, "x").homed

    done = run_until(client, accepted(move_absolute.sync(
        axis="x", client=client, body=MoveBody(position=300.0, velocity=200.0))))
    assert done.state == CommandState.DONE
    assert status(client, "x").set_position == 300.0

    # y follows x at twice its travel.
    run_until(client, accepted(gear_in.sync(
        axis="y", client=client, body=GearInBody(master="x", ratio_numerator=2.0, ratio_denominator=1))))
    y0 = status(client, "y").set_position
    run_until(client, accepted(move_absolute.sync(
        axis="x", client=client, body=MoveBody(position=400.0, velocity=100.0))))
    assert status(client, "x").set_position == 400.0
    assert status(client, "y").set_position == y0 + 200.0
    run_until(client, accepted(gear_out.sync(axis="y", client=client, body=EmptyBody())))

    # A drive fault mid-move: the move ends in Error, the axis in error_stop; reset, power, go on.
    m = accepted(move_absolute.sync(axis="x", client=client, body=MoveBody(position=900.0, velocity=100.0)))
    run_for(client, 1.0)
    assert inject_fault.sync_detailed(
        axis="x", client=client, body=SimFaultType0(kind=SimFaultType0Kind.DRIVE_FAULT, code=0x2310)).status_code == 204
    ended = run_until(client, m, max_seconds=10)
    assert ended.state == CommandState.ERROR
    assert status(client, "x").state == "error_stop"
    inject_fault.sync_detailed(axis="x", client=client, body=SimFaultType5(kind=SimFaultType5Kind.CLEAR))
    run_until(client, accepted(reset.sync(axis="x", client=client, body=EmptyBody())))
    run_until(client, accepted(power.sync(axis="x", client=client, body=PowerBody())))
    stood = status(client, "x").set_position

    done = run_until(client, accepted(move_absolute.sync(
        axis="x", client=client, body=MoveBody(position=0.0, velocity=200.0))))
    assert done.state == CommandState.DONE
    assert status(client, "x").set_position == 0.0
    assert 400.0 < stood < 900.0

    # The rest of the minute: the machine stands, the clock says so.
    c = get_clock.sync(client=client)
    a = run_for(client, round(60.0 - c.time_s, 3))
    assert a.clock.time_s == 60.0, a.clock
    assert a.clock.cycle == 60_000
    assert status(client, "x").state == "standstill"
    print(f"60 s of machine time in {time.monotonic() - wall:.2f} s of wall time")
