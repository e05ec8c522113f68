# The two set-up commands of the README: `make tour` (build, run the main job) and
# `make test` (build, run every test). PYTHON may name another interpreter.
PYTHON ?= python3

.PHONY: install tour lint test bench compare gallery

install:
	$(PYTHON) -m pip install -e ".[test,charts]"

tour: install
	$(PYTHON) -m varmech tour --out out/tour

# The guards: formatting, clippy on every target of both crates, ruff, mypy on the package, and
# stubtest of the binding against its stub _core.pyi.
lint: install
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	$(PYTHON) -m ruff check python tests benches
	$(PYTHON) -m mypy
	$(PYTHON) -m mypy.stubtest varmech._core

test: lint
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
