"""Marks the test modules share."""

from __future__ import annotations

import pytest

from cadcnc.testing.rs274 import RS274

needs_rs274 = pytest.mark.skipif(RS274 is None, reason="LinuxCNC rs274 not installed "
                                 "(Debian package linuxcnc-uspace; .ci/run installs it)")
