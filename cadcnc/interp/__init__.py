"""The interpolation core: the stepper (plain reference and compiled kernel), its cycle's
mathematics, records and error bounds. No OCCT."""
