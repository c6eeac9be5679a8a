"""The interpolation core; importing it registers the compiled stepper."""

from . import compiled  # noqa: F401 (Stepper.compiled_class)
