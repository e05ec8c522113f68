# The two set-up commands of the README: `make tour` (build, run the main job) and
# `make test` (build, run every test). PYTHON may name another interpreter.
PYTHON ?= python3

.PHONY: install tour lint guards test guards-then-rust test-rust test-python docs wheel-check test-aarch64 bench compare gallery campaign

# The extra `test` is the dependency groups test and dev of pyproject.toml, which need pip >= 25.1
# (`pip install --group dev`): the extra keeps `make test` working with the pip a fresh Python has.
install:
	$(PYTHON) -m pip install -e ".[test,charts]"

tour: install
	$(PYTHON) -m varmech tour --out out/tour

# The guards: formatting, clippy on every target of both crates, the rustdoc links of both (the
# core's public docs, the binding's private ones: a cdylib has no public Rust API), ruff, mypy on
# the package, and stubtest of the binding against its stub _core.pyi.
lint: install guards

guards:
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" cargo doc --no-deps -p varmech
	RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --document-private-items -p varmech-python
	$(PYTHON) -m ruff check python tests benches docs
	$(PYTHON) -m mypy
	$(PYTHON) -m mypy.stubtest varmech._core

# The documentation site (Sphinx, numpydoc, pydata theme, MyST pages, a sphinx-gallery whose
# examples run now): docs/_build/html. Warnings are errors; `make test` builds it afresh.
SPHINX = $(PYTHON) -m sphinx -b html -W --keep-going docs docs/_build/html
docs: install
	$(SPHINX)

# Every test but the packaging check (the tests marked `wheel`, run by `make wheel-check`).
# --workspace: the features of the binding's build too, so that the core's release build from the
# editable install is reused (rust/python/Cargo.toml's `either`); the binding itself has no tests.
# Two jobs side by side, each one's output kept together: the guards and then the Rust tests,
# and pytest. The release build of the Rust test crate (codegen-units = 1) and pytest each keep a
# core busy for minutes, so pytest starts with the guards (CI is bound by the two cores' work).
test: install
	$(MAKE) --jobs=2 --output-sync=target guards-then-rust test-python
	$(SPHINX) -E -a

guards-then-rust: guards
	$(MAKE) test-rust

# Cargo schedules its own jobs: without make's jobserver, which it cannot join from a sub-make.
test-rust:
	env -u MAKEFLAGS -u MFLAGS cargo test --release --workspace

# pytest's own workers, one per core (pytest-xdist): a core the Rust job leaves idle when it
# finishes takes tests from the other (worksteal), so neither job waits on the other.
test-python:
	$(PYTHON) -m pytest -q -m "not wheel" -n auto --dist worksteal

# The packaging check (tests/python/test_wheel.py): a manylinux2014 wheel built with zig, checked by
# auditwheel, installed into a fresh venv and running the quickstart. A release build of its own
# (zig's target dir, so nothing of the editable install is reused): minutes, hence not part of
# `make test`; run it before a release (release.yml builds the release wheels).
wheel-check: install
	$(PYTHON) -m pytest -q -m wheel tests/python/test_wheel.py

# The core's tests on aarch64 (the N-body kernel's scalar path there), cross-built and run under
# qemu: needs `rustup target add aarch64-unknown-linux-gnu` and Debian's gcc-aarch64-linux-gnu and
# qemu-user. About 10 minutes; not part of `make test`.
AARCH64 = CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc \
	CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="qemu-aarch64 -L /usr/aarch64-linux-gnu" \
	CC_aarch64_unknown_linux_gnu=aarch64-linux-gnu-gcc
test-aarch64:
	$(AARCH64) cargo test --release --target aarch64-unknown-linux-gnu --test core

# The property tests' long campaign: the core's proptest properties with PROPTEST_CASES cases
# each, then tests/python/property_campaign.py: random models, states, methods and steps, each
# case in a process of its own, for CAMPAIGN_MINUTES (or CAMPAIGN_EXAMPLES cases), new ones each
# seed (CAMPAIGN_SEED repeats one); it prints the outcomes' counts and every case that broke a
# property (also written to campaign_failures.jsonl); a failed core property does not stop the
# Python cases. CI runs a few of each (make test).
CAMPAIGN_MINUTES ?= 15
CAMPAIGN_EXAMPLES ?= 100000
CAMPAIGN_SEED ?= $(shell date +%s)
PROPTEST_CASES ?= 1000
campaign: install
	-env -u MAKEFLAGS -u MFLAGS PROPTEST_CASES=$(PROPTEST_CASES) cargo test --release --test core properties
	$(PYTHON) tests/python/property_campaign.py --minutes $(CAMPAIGN_MINUTES) --examples $(CAMPAIGN_EXAMPLES) --seed $(CAMPAIGN_SEED)

bench:
	cargo bench --bench steps

compare:
	$(PYTHON) -m pip install -e ".[bench]"
	$(PYTHON) benches/compare.py

gallery:
	$(PYTHON) -m pip install -e ".[bench]"
	$(PYTHON) benches/gallery.py
