# The two set-up commands of the README: `make tour` (build, run the main job) and
# `make test` (build, run every test). PYTHON may name another interpreter.
PYTHON ?= python3

.PHONY: install tour test bench compare gallery

install:
	$(PYTHON) -m pip install -e ".[test,charts]"

tour: install
	$(PYTHON) -m varmech tour --out out/tour

test: install
	cargo test --release
	$(PYTHON) -m pytest -q

bench:
	cargo bench --bench steps

compare:
	$(PYTHON) -m pip install -e ".[bench]"
	$(PYTHON) benches/compare.py

gallery:
	$(PYTHON) -m pip install -e ".[bench]"
	$(PYTHON) benches/gallery.py
