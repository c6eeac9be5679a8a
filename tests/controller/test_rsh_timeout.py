"""A linuxcncrsh that stops answering is a HalError naming the command, not a bare
TimeoutError from the socket."""

from __future__ import annotations

import socket
import threading

import pytest

from cadcnc.controller.hal import linuxcnc_sim as sim
from cadcnc.controller.hal.session import HalError


def test_a_silent_linuxcncrsh_is_a_hal_error_naming_the_command():
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    port = server.getsockname()[1]
    held = []

    def accept_and_say_nothing() -> None:
        conn, _ = server.accept()
        held.append(conn)

    t = threading.Thread(target=accept_and_say_nothing)
    t.start()
    try:
        with pytest.raises(HalError, match=r"did not answer 'hello .*' within 0.3 s"):
            sim.Rsh(port, "c", "e", timeout=0.3)
    finally:
        t.join()
        for c in held:
            c.close()
        server.close()
