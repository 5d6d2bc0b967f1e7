"""An MES script: what a line controller does with motiond through the Python client that
openapi-python-client generates from openapi/openapi.json (nothing hand-written in between).

    python tests/client/mes_example.py http://127.0.0.1:8080

with the generated package `motiond_client` on PYTHONPATH (tests/client/check.sh generates it
into target/client/python and runs this against a fresh motiond). Exits non-zero on failure.
"""

import sys

from motiond_client import Client
from motiond_client.api.axes import axis_status, reset_following_error_peak
from motiond_client.api.commands import home, move_absolute, move_relative, power
from motiond_client.models import (
    CommandResource,
    CommandState,
    EmptyBody,
    HomeBody,
    MoveBody,
    MoveRelativeBody,
    PeakResetResource,
    PowerBody,
    StatusResource,
)


def command(what: str, r: object) -> CommandResource:
    """The command resource of an accepted command, or the problem the server answered."""
    if not isinstance(r, CommandResource):
        sys.exit(f"mes-example: {what} refused: {r}")
    return r


def main(base_url: str) -> None:
    # motiond answers loopback host names only and wants JSON bodies: the generated client
    # sends `Host: 127.0.0.1:PORT` and every body as application/json by itself.
    client = Client(base_url=base_url, headers={"X-Client-Id": "mes-example"}, timeout=30.0)
    with client:
        r = command("power", power.sync(axis="x", client=client, body=PowerBody(enable=True), wait=True, timeout_ms=5000))
        assert r.outputs.status, f"x not powered: {r}"

        r = command("home", home.sync(axis="x", client=client, body=HomeBody(), wait=True, timeout_ms=30000))
        assert r.state == CommandState.DONE, f"homing did not finish: {r.state} {r}"

        r = command(
            "move-absolute",
            move_absolute.sync(axis="x", client=client, body=MoveBody(position=250.0, velocity=200.0), wait=True, timeout_ms=20000),
        )
        assert r.state == CommandState.DONE, f"move-absolute: {r.state}"

        r = command(
            "move-relative",
            move_relative.sync(axis="x", client=client, body=MoveRelativeBody(distance=-50.0, velocity=200.0), wait=True, timeout_ms=20000),
        )
        assert r.state == CommandState.DONE, f"move-relative: {r.state}"

        # An operation without parameters: its `{}` body makes the request application/json.
        peak = reset_following_error_peak.sync(axis="x", client=client, body=EmptyBody())
        if not isinstance(peak, PeakResetResource):
            sys.exit(f"mes-example: peak reset refused: {peak}")

        st = axis_status.sync(axis="x", client=client)
        if not isinstance(st, StatusResource):
            sys.exit(f"mes-example: status refused: {st}")
        s = st.status
        assert abs(s.set_position - 200.0) < 1e-6, f"set position {s.set_position}, not 200"
        assert abs(s.actual_position - 200.0) < 0.05, f"actual position {s.actual_position}, not 200"
        assert s.homed, "x not homed"
        print(f"mes-example: x powered, homed, at {s.actual_position:.3f} {st.status.state.value} (set {s.set_position})")


if __name__ == "__main__":
    main(sys.argv[1])
