# Convenience targets; the README's two commands do the same without make.
.PHONY: setup demo test fixtures perf validation
setup:
	python3 -m venv .venv && .venv/bin/pip install -q -e '.[test]'
demo: setup
	.venv/bin/cadcnc demo
test: setup
	.venv/bin/python -m pytest -q
fixtures:
	.venv/bin/python fixtures/build_fixtures.py
perf:
	.venv/bin/python -m benchmarks perf
validation:
	.venv/bin/python docs/scripts/validation_report.py
