"""Small pure functions for the interpolation cycle: numpy, numba and math only, no OCCT.

Everything here is written so ``numba.njit`` can compile it unchanged; the caller decides
whether to compile.
"""
