"""HAL in the loop and the LinuxCNC baseline: every HAL tool runs in a subprocess.

Nothing here imports LinuxCNC's Python modules; the library only writes .hal/.ini files,
starts ``halrun``/``linuxcnc`` and reads what ``halsampler`` prints.
"""

from .loop import HalLoopResult, run_hal_loop, summary, write_stream_txt
from .session import HalError, HalInterrupted, HalSession, hal_available, rtapi_pids

__all__ = ["HalError", "HalInterrupted", "HalLoopResult", "HalSession", "hal_available",
           "rtapi_pids", "run_hal_loop", "summary", "write_stream_txt"]
