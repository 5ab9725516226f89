# dqhand — `make demo` sets up and runs the main job; `make test` sets up and runs every test.
# Both install what a fresh machine lacks (the Rust toolchain and Node.js are expected; Debian's
# chromium is installed for the browser tests when running as root).

CARGO ?= cargo
NPM ?= npm
CHROMIUM ?= /usr/bin/chromium
WEBXR_HAND := third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb
VALIDATOR := third_party/node_modules/gltf-validator/package.json
# Hand poses others recorded (Quest hand tracking, via handy-work and IWER): the gesture tests' outside data.
OUTSIDE_POSES := third_party/node_modules/handy-work/poses/fist.handpose third_party/node_modules/iwer/lib/device/configs/hand/pinch.js
VIEWER_DEPS := viewer/node_modules/.package-lock.json
VIEWER_DIST := viewer/dist/index.html
HAND_FILES := viewer/public/hands/right.glb viewer/public/hands/left.glb
# The engine's web builds as the npm package and the page load them (make package-wasm).
PACKAGE_WASM := $(addprefix packages/dqhand/wasm/,dqhand_wasm.js dqhand_wasm.d.ts dqhand_wasm_bg.wasm dqhand_wasm_simd_bg.wasm)

.PHONY: demo test build viewer assets chromium figures bench bench-web bench-mediapipe bench-peers loadtest fuzz clean recordings features examples gestures wasm-check wasm package-wasm package dqs-package bench-dqs python synth-figure

# The live viewer on the built-in hand: prints the URL (and opens a browser when there is a desktop).
demo: build viewer
	./target/release/dqhand demo

build:
	$(CARGO) build --release --locked -p dqhand-cli

# Sample recordings of the gesture library: synthetic (made from our own kinematics by
# `dqhand synthesize`, seeded, labelled so in their .labels.json), not captured from a person.
# The tests replay them; no command needs them (`demo --scene` makes its grasps itself).
RECORDINGS := crates/dqhand/data/recordings
DQHAND_DEBUG := target/debug/dqhand

recordings: $(RECORDINGS)/gestures-joints.jsonl

$(RECORDINGS)/gestures-joints.jsonl: $(wildcard crates/*/src/*.rs crates/*/src/*/*.rs)
	$(CARGO) build --locked -p dqhand-cli
	mkdir -p $(RECORDINGS)
	$(DQHAND_DEBUG) synthesize --format joints --seed 1 --length 0.18 --breadth 0.08 --side right --out $(RECORDINGS)/gestures-joints.jsonl
	$(DQHAND_DEBUG) synthesize --format landmarks --seed 3 --length 0.17 --breadth 0.08 --side left --out $(RECORDINGS)/gestures-landmarks.jsonl
	$(DQHAND_DEBUG) synthesize --format glove --seed 2 --length 0.2 --breadth 0.09 --side right --out $(RECORDINGS)/gestures-glove.csv
	$(DQHAND_DEBUG) synthesize --scene grasp --side right --out $(RECORDINGS)/grasp-joints.jsonl

# The page (TypeScript + three.js, built by Vite into viewer/dist, which `dqhand demo` or any
# static host serves): it runs the engine itself, the package's WebAssembly (package-wasm).
viewer: package-wasm $(VIEWER_DIST)

$(VIEWER_DEPS): viewer/package.json viewer/package-lock.json
	cd viewer && $(NPM) ci --no-audit --no-fund
	touch $@

$(VIEWER_DIST): $(VIEWER_DEPS) viewer/index.html viewer/vite.config.ts viewer/tsconfig.json $(wildcard viewer/src/*) $(wildcard packages/dqhand/src/*) $(PACKAGE_WASM) $(HAND_FILES)
	cd viewer && $(NPM) run build

# The built-in hands beside the page (Vite copies viewer/public into dist): the page's engine
# loads them in milliseconds instead of generating them (seconds in WebAssembly). The same
# hands, written by the command a user would run (`dqhand hand --out`).
# Written to target/ first and copied only when they changed: an edit elsewhere in the
# library writes them again (two seconds) but does not rebuild the page.
$(HAND_FILES) &: $(wildcard crates/dqhand/src/*.rs crates/dqhand/src/*/*.rs) crates/dqhand-cli/src/hand.rs crates/dqhand-cli/src/main.rs Cargo.lock
	$(CARGO) build --locked -p dqhand-cli
	mkdir -p viewer/public/hands target/hands
	for side in right left; do $(DQHAND_DEBUG) hand --side $$side --out target/hands/$$side.glb || exit 1; done
	install -C -m 644 target/hands/right.glb target/hands/left.glb viewer/public/hands/

# Third-party test assets and tools come from the npm registry through third_party/package-lock.json;
# nothing third-party is committed.
assets: $(WEBXR_HAND) $(VALIDATOR) $(OUTSIDE_POSES)

$(WEBXR_HAND) $(VALIDATOR) $(OUTSIDE_POSES) &: third_party/package.json third_party/package-lock.json
	cd third_party && $(NPM) ci --no-audit --no-fund
	touch $(WEBXR_HAND) $(VALIDATOR) $(OUTSIDE_POSES)

# Debian's Chromium drives the browser tests and the figures (no browser download).
chromium:
	@test -x $(CHROMIUM) || { \
	  if [ "$$(id -u)" = 0 ]; then apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; \
	  else echo "make: $(CHROMIUM) missing: install Debian's chromium (sudo apt-get install chromium)" >&2; exit 1; fi; }

# The skinning kernels this machine's CPU runs (its /proc/cpuinfo flags, as the kernels'
# run-time check reads them): the kernel tests must run them, not skip them.
CPU_FLAGS := $(shell grep -m1 '^flags' /proc/cpuinfo 2>/dev/null)
has_flags = $(if $(strip $(foreach f,$(1),$(if $(filter $(f),$(CPU_FLAGS)),,missing))),,yes)
comma := ,
DQHAND_REQUIRE_KERNELS ?= $(subst $() $(),$(comma),$(strip \
  $(if $(call has_flags,avx2 fma avx512f avx512vl avx512dq),avx512) $(if $(call has_flags,avx2 fma),avx2)))

# The library's features, each built alone (a feature must not lean on another it does not
# name), the core first: kinematics and the deformers on glam.
LIB_FEATURES := gltf hand interaction metrics rayon synthetic

features:
	$(CARGO) check --locked -p dqhand --no-default-features --lib --examples
	for f in $(LIB_FEATURES); do $(CARGO) check --locked -p dqhand --no-default-features --features $$f --lib --examples || exit 1; done
	$(MAKE) wasm-check

# The whole library for WebAssembly (the browser engine to come builds on it): no C or C++
# dependency, nothing x86-only outside its kernels' cfg.
wasm-check:
	rustup target list --installed | grep -qx wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown
	$(CARGO) check --locked -p dqhand --target wasm32-unknown-unknown --no-default-features --features $(subst $() $(),$(comma),$(LIB_FEATURES)) --lib

# The engine in WebAssembly (crates/dqhand-wasm) for Node and for the browser's ES modules, in
# target/wasm/{node,web}: bound by wasm-bindgen-cli at exactly Cargo.lock's wasm-bindgen
# version (the two must match), built once into .tools/ (npm's wasm-pack downloads binaries).
WASM_BINDGEN_VERSION := $(shell awk '$$0 == "name = \"wasm-bindgen\"" { getline; gsub(/[^0-9.]/, ""); print }' Cargo.lock)
WASM_BINDGEN := $(CURDIR)/.tools/wasm-bindgen-$(WASM_BINDGEN_VERSION)/bin/wasm-bindgen
WASM_OUT := target/wasm32-unknown-unknown/release/dqhand_wasm.wasm
# The same engine with WebAssembly's 128-bit SIMD (the simd128 kernel), in its own target
# directory (other compiler flags), for engines that validate it.
WASM_SIMD_OUT := target/wasm-simd/wasm32-unknown-unknown/release/dqhand_wasm.wasm

$(WASM_BINDGEN):
	$(CARGO) install --locked wasm-bindgen-cli --version $(WASM_BINDGEN_VERSION) --root $(CURDIR)/.tools/wasm-bindgen-$(WASM_BINDGEN_VERSION)

wasm: $(WASM_BINDGEN)
	rustup target list --installed | grep -qx wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown
	$(CARGO) build --locked --release -p dqhand-wasm --target wasm32-unknown-unknown
	RUSTFLAGS="-C target-feature=+simd128" CARGO_TARGET_DIR=target/wasm-simd $(CARGO) build --locked --release -p dqhand-wasm --target wasm32-unknown-unknown
	$(WASM_BINDGEN) --target nodejs --out-dir target/wasm/node $(WASM_OUT)
	$(WASM_BINDGEN) --target web --out-dir target/wasm/web $(WASM_OUT)
	$(WASM_BINDGEN) --target nodejs --out-dir target/wasm/node-simd $(WASM_SIMD_OUT)
	$(WASM_BINDGEN) --target web --out-dir target/wasm/web-simd $(WASM_SIMD_OUT)
	@for b in web web-simd; do ls -l target/wasm/$$b/dqhand_wasm_bg.wasm | awk -v b=$$b '{ printf "%s: %d bytes, ", b, $$5 }'; gzip -9c target/wasm/$$b/dqhand_wasm_bg.wasm | wc -c | awk '{ print $$1 " gzipped" }'; done

# The library's examples, run (cargo test only builds them).
examples: recordings
	mkdir -p out/examples
	$(CARGO) run --locked -q -p dqhand --no-default-features --example skin_into_buffer
	$(CARGO) run --locked -q -p dqhand --example skin_a_pose -- out/examples/ok.glb
	$(CARGO) run --locked -q -p dqhand --example gestures_from_a_recording -- $(RECORDINGS)/gestures-joints.jsonl
	$(CARGO) run --locked -q -p dqhand --features synthetic --example grasp_the_ball

# The npm package `dqhand` (packages/dqhand): the web build of the engine, with and without
# SIMD (one glue module serves both: wasm-bindgen writes the same for each), its TypeScript
# compiled, packed into target/npm/dqhand-<version>.tgz as `npm publish` would ship it.
# `install -C` copies only what changed, so an unchanged engine does not rebuild the page.
package-wasm: wasm
	cmp target/wasm/web/dqhand_wasm.js target/wasm/web-simd/dqhand_wasm.js
	mkdir -p packages/dqhand/wasm
	install -C -m 644 target/wasm/web/dqhand_wasm.js target/wasm/web/dqhand_wasm.d.ts target/wasm/web/dqhand_wasm_bg.wasm packages/dqhand/wasm/
	install -C -m 644 target/wasm/web-simd/dqhand_wasm_bg.wasm packages/dqhand/wasm/dqhand_wasm_simd_bg.wasm

$(PACKAGE_WASM):
	$(MAKE) package-wasm

package: package-wasm
	mkdir -p target/npm
	cd packages/dqhand && $(NPM) ci --no-audit --no-fund && rm -rf dist && npx tsc -p tsconfig.json && npm pack --pack-destination ../../target/npm

# The npm package `three-dqs` (packages/three-dqs): dual quaternion skinning for any three.js
# SkinnedMesh, its TypeScript compiled and packed into target/npm/three-dqs-<version>.tgz; its
# conformance page and example are built by the browser tests (viewer/tests/dqs.test.ts).
dqs-package:
	mkdir -p target/npm
	cd packages/three-dqs && $(NPM) ci --no-audit --no-fund && npx tsc -p tsconfig.test.json && rm -rf dist && npx tsc -p tsconfig.json && npm pack --pack-destination ../../target/npm

# Rust tests (unit, property, golden, CLI, server, doctests; their temporary files, the
# doctests' binaries among them, under target/ rather than a small /tmp), the features alone and the
# examples, the Khronos glTF validator on what we write, then the page: protocol unit tests and
# browser tests against a real `dqhand demo`.
test: assets viewer chromium recordings package dqs-package
	mkdir -p target/tmp
	DQHAND_REQUIRE_KERNELS=$(DQHAND_REQUIRE_KERNELS) TMPDIR=$(CURDIR)/target/tmp $(CARGO) test --locked --workspace
	$(MAKE) features examples
	node --test tests/
	cd viewer && DQHAND_BIN=$(CURDIR)/target/debug/dqhand CHROMIUM=$(CHROMIUM) npx vitest run
	$(MAKE) python

# docs/figures/*.png: the paper's Figures 5-7 and 9 on our hand, rendered by the real page
# (Figure 9 makes its own scripted grasp recording with the release binary).
figures: build viewer chromium dqs-package synth-figure
	cd viewer && DQHAND_BIN=$(CURDIR)/target/release/dqhand CHROMIUM=$(CHROMIUM) node scripts/figures.mjs

# docs/figures/synth-samples.png: 12 samples of a synthetic data set, read back (docs/datasets.md).
synth-figure: python
	$(PY_PKG)/.venv/bin/python $(PY_PKG)/tools/synth_figure.py docs/figures/synth-samples.png

# Coverage-guided fuzzing of every parser (nightly toolchain + cargo-fuzz), FUZZ_SECONDS each:
# the stream's frame and topology readers, viewer commands on a live session, pose files, glTF
# import, scene object meshes (glTF), recordings (JSON records, glove CSV), scene files, the
# JSON settings (input configurations, glove tables and calibrations, gesture definitions),
# and the server's HTTP request heads and WebSocket frames (its own reading code, compiled in).
# Seeds: fuzz/seeds, the wire-format golden vectors, the WebXR generic hand. Without a
# sanitizer: the library is safe Rust apart from the AVX2 and AVX-512 kernels (checked against
# a reference by the tests), and AddressSanitizer makes building the hand the targets pose too slow.
FUZZ_SECONDS ?= 60
FUZZ_TARGETS := frame command pose_file gltf object_mesh json_record glove_csv scene settings http_head websocket

fuzz: assets
	command -v cargo-fuzz >/dev/null || $(CARGO) install cargo-fuzz --locked
	for t in $(FUZZ_TARGETS); do mkdir -p fuzz/corpus/$$t; done
	cp viewer/tests/fixtures/*.bin fuzz/corpus/frame/
	cp fuzz/seeds/command/* fuzz/corpus/command/
	cp fuzz/seeds/pose_file/* fuzz/corpus/pose_file/
	cp fuzz/seeds/json_record/* fuzz/corpus/json_record/
	cp fuzz/seeds/glove_csv/* fuzz/corpus/glove_csv/
	cp fuzz/seeds/scene/* fuzz/corpus/scene/
	cp fuzz/seeds/settings/* fuzz/corpus/settings/
	cp fuzz/seeds/http_head/* fuzz/corpus/http_head/
	cp fuzz/seeds/websocket/* fuzz/corpus/websocket/
	cp $(WEBXR_HAND) fuzz/corpus/gltf/
	cp $(WEBXR_HAND) fuzz/corpus/object_mesh/
	for t in $(FUZZ_TARGETS); do $(CARGO) +nightly fuzz run --sanitizer none $$t fuzz/corpus/$$t -- -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=4096 || exit 1; done

bench: build
	./target/release/dqhand bench
	./target/release/dqhand bench --stream 3

# three-dqs beside three.js's own linear skinning in headless Chromium, 1, 10 and 100 hands
# (docs/performance.md, "Dual quaternion skinning for three.js").
bench-dqs: build chromium dqs-package
	cd viewer && CHROMIUM=$(CHROMIUM) node scripts/dqs-bench.mjs

# The engine in WebAssembly timed in headless Chromium beside the native kernels, in one run:
# deformers of both builds, the page's interaction frame, load to the first drawn hand
# (docs/performance.md, "The engine in the browser").
bench-web: build viewer chromium recordings
	cd viewer && CHROMIUM=$(CHROMIUM) node scripts/bench-web.mjs

# MediaPipe Hands on 100 random views of the built-in hand in the library's gestures, in the
# page (docs/realism.md, "Does MediaPipe see it?"); SEED=2 for the second set.
SEED ?= 1
bench-mediapipe: viewer chromium
	cd viewer && CHROMIUM=$(CHROMIUM) node scripts/mediapipe-views.mjs --seed $(SEED) --json $(CURDIR)/target/mediapipe-views-$(SEED).json

# The viewer server under load and abuse (1, 10, 64 viewers; malformed flood; slowloris; a
# slow reader), measured; `make test` runs a short version that asserts behaviour only.
loadtest: build
	./target/release/dqhand loadtest

# dqhand beside its peers on one frame of the built-in hand (bench/peers): libigl's dqs and
# lbs_matrix, a NumPy LB and DQB, three.js's CPU skinning; one table, also in
# bench/peers/results.md. Each peer has its own environment there, made here: a venv from
# requirements.txt (libigl 2.5.1's wheels need Python 3.10-3.12: PYTHON=python3.12 to pick
# one) and node_modules from package-lock.json.
PYTHON ?= python3
PEERS := bench/peers
PEERS_VENV := $(PEERS)/.venv/installed
PEERS_DEPS := $(PEERS)/node_modules/.package-lock.json

bench-peers: build $(PEERS_VENV) $(PEERS_DEPS)
	./target/release/dqhand export-skinning --out out/peers
	node $(PEERS)/three.mjs out/peers
	$(PEERS)/.venv/bin/python $(PEERS)/peers.py out/peers --out $(PEERS)/results.md

$(PEERS_VENV): $(PEERS)/requirements.txt
	@$(PYTHON) -c 'import sys; sys.exit(not (3, 10) <= sys.version_info[:2] <= (3, 12))' || \
	  { echo "make: bench-peers needs Python 3.10 to 3.12 for libigl 2.5.1 (PYTHON=python3.12 make bench-peers)" >&2; exit 1; }
	rm -rf $(PEERS)/.venv
	$(PYTHON) -m venv $(PEERS)/.venv
	$(PEERS)/.venv/bin/pip install --quiet --disable-pip-version-check -r $<
	touch $@

$(PEERS_DEPS): $(PEERS)/package.json $(PEERS)/package-lock.json
	cd $(PEERS) && $(NPM) ci --no-audit --no-fund
	touch $@

# The Python package (crates/dqhand-py, `import dqhand`): maturin builds its abi3 wheel into
# target/wheels; a virtual environment of its own (crates/dqhand-py/.venv, from
# requirements-dev.txt, with Ray Data and pyarrow for the data sets) installs it and runs its
# pytest suite, which compares the skin with a NumPy reference and with the command line's (the
# debug binary `cargo test` builds) and makes a 20,000-sample data set on a local Ray with 2
# CPUs (docs/datasets.md); then a fresh environment installs the wheel alone (NumPy from PyPI)
# and skins a hand.
PY_PKG := crates/dqhand-py
PY_VENV := $(PY_PKG)/.venv/installed

python: assets $(PY_VENV)
	$(CARGO) build --locked -p dqhand-cli
	$(PY_PKG)/.venv/bin/maturin build --release --locked --quiet -m $(PY_PKG)/Cargo.toml --interpreter $(PY_PKG)/.venv/bin/python --out target/wheels
	$(PY_PKG)/.venv/bin/pip install --quiet --disable-pip-version-check --force-reinstall --no-deps target/wheels/dqhand-*-abi3-*.whl
	DQHAND_BIN=$(CURDIR)/target/debug/dqhand $(PY_PKG)/.venv/bin/python -m pytest -q $(PY_PKG)/tests
	# The wheel as a user installs it: a fresh environment, its dependencies from PyPI.
	rm -rf target/tmp/fresh-venv && $(PYTHON) -m venv target/tmp/fresh-venv
	target/tmp/fresh-venv/bin/pip install --quiet --disable-pip-version-check target/wheels/dqhand-*-abi3-*.whl
	cd target/tmp && fresh-venv/bin/python -c 'import dqhand, numpy; h = dqhand.Hand.builtin(vertices=2000); v = h.skin(numpy.zeros((2, len(h.dof_names)))); assert v.shape == (2, len(h.rest_vertices), 3), v.shape; print("fresh environment:", h)'

$(PY_VENV): $(PY_PKG)/requirements-dev.txt
	rm -rf $(PY_PKG)/.venv
	$(PYTHON) -m venv $(PY_PKG)/.venv
	$(PY_PKG)/.venv/bin/pip install --quiet --disable-pip-version-check -r $<
	touch $@

clean:
	$(CARGO) clean
	rm -rf out third_party/node_modules viewer/node_modules viewer/dist viewer/public packages/dqhand/wasm packages/dqhand/dist packages/dqhand/node_modules $(RECORDINGS) $(PEERS)/.venv $(PEERS)/node_modules $(PY_PKG)/.venv

# The built-in gesture classifier, trained on the tuning split of varied hands (deterministic;
# `dqhand gesture-bench --outside third_party/node_modules` reports on the held-out split).
gestures:
	cargo build --release --locked -p dqhand-cli
	target/release/dqhand train-gestures --out crates/dqhand/data/gestures.json
