# dqhand — `make demo` sets up and runs the main job; `make test` sets up and runs every test.
# Both install what a fresh machine lacks (the Rust toolchain is expected, Node for assets).

CARGO ?= cargo
NPM ?= npm
WEBXR_HAND := third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb
VALIDATOR := third_party/node_modules/gltf-validator/package.json

.PHONY: demo test build assets bench clean

demo: build
	./target/release/dqhand demo --out out/demo

build:
	$(CARGO) build --release --locked -p dqhand-cli

# Third-party test assets and tools come from the npm registry through third_party/package-lock.json;
# nothing third-party is committed.
assets: $(WEBXR_HAND) $(VALIDATOR)

$(WEBXR_HAND) $(VALIDATOR) &: third_party/package.json third_party/package-lock.json
	cd third_party && $(NPM) ci --no-audit --no-fund
	touch $(WEBXR_HAND) $(VALIDATOR)

# Rust tests (unit, property, golden, CLI), then the Khronos glTF validator on what we write.
test: assets
	$(CARGO) test --locked --workspace
	node --test tests/

bench: build
	./target/release/dqhand bench

clean:
	$(CARGO) clean
	rm -rf out third_party/node_modules
