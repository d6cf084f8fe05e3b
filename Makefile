# ringside: `make` builds build/ringside.  See README.md.
#
#   make            build (installs missing Debian packages first)
#   make test       build and run every test; ends with "N passed, N failed, N skipped"
#   make test-service  the service end to end (PostgreSQL, Chromium; docs/service.md)
#   make web        hls.js from npm, the dashboard's live-stream player (docs/service.md)
#   make check-layers  fail if a lower layer includes a higher one, or a function or a
#                      service file outgrows its size (make test runs it too)
#   make asan       the suites and cases of tests/asan.tier under AddressSanitizer +
#                   UBSan (build-asan/; docs/testing.md); make asan-all: every suite
#   make debug      -O0 build with GL error checks in build-debug/
#   make demo       the main job on the bundled default (see README)
#   make bench      benchmarks
#   make man        manual pages, bash completion, example config in build/man, build/dist
#   make install PREFIX=/usr/local [DESTDIR=...]   (make uninstall removes it all)
#   make clean
#
# Variables: BUILD (output dir), OPT, SAN=1, DEBUG=1, WERROR=1 (on when CI=true),
# T=name (make test T=shader runs tests/test_shader only), ONLY="egl ffmpeg"
# (configure only those backends; a new BUILD dir, as tools/gpu-bundle.sh does).

BUILD   ?= build
# One spelling per directory: BUILD=$(CURDIR)/build (tests/test_cli.sh's
# install check passes it so) must name the same targets as BUILD=build, or
# the dependency files written under one spelling are ignored under the
# other and a changed header leaves stale objects behind.
override BUILD := $(patsubst $(CURDIR)/%,%,$(BUILD))
PREFIX  ?= /usr/local
CC      ?= cc
OPT     ?= -O2
T       ?=

ifeq ($(CI),true)
WERROR ?= 1
endif

# Determinism (see the runtime docs): no fused multiply-add, no fast-math.
# Messages go into fixed buffers and are cut on purpose: no truncation warning.
CFLAGS_BASE := -std=c11 -D_POSIX_C_SOURCE=200809L -Wall -Wextra -Wshadow -Wstrict-prototypes \
               -Wno-format-truncation -ffp-contract=off -fno-fast-math -g -MMD -MP
ifeq ($(WERROR),1)
CFLAGS_BASE += -Werror
endif
ifeq ($(SAN),1)
CFLAGS_BASE += -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -DRS_SANITIZE
LDFLAGS_SAN := -fsanitize=address,undefined
OPT := -O1
endif
ifeq ($(DEBUG),1)
CFLAGS_BASE += -DRS_DEBUG
OPT := -O0
endif

STAMPS := build/deps
# Goals that build nothing must not install packages or configure.
NOBUILD_GOALS := clean help uninstall check-layers
ifneq ($(filter clean,$(MAKECMDGOALS)),)
ifneq ($(filter-out clean,$(MAKECMDGOALS)),)
$(error run 'make clean' on its own, then 'make $(filter-out clean,$(MAKECMDGOALS))')
endif
endif
ifneq ($(MAKECMDGOALS),)
ifeq ($(filter-out $(NOBUILD_GOALS),$(MAKECMDGOALS)),)
SKIP_CONFIG := 1
endif
endif
ifneq ($(SKIP_CONFIG),1)
-include $(BUILD)/config.mk
# Objects depend on the compile flags: `make SAN=1` after `make` rebuilds.
FLAGS_SIG := $(CC) $(CFLAGS_BASE) $(OPT) $(EXTRA_CFLAGS) $(CURDIR)
$(shell mkdir -p $(BUILD) && (echo '$(FLAGS_SIG)' | cmp -s - $(BUILD)/flags || echo '$(FLAGS_SIG)' > $(BUILD)/flags))
endif

CFLAGS  = $(CFLAGS_BASE) $(OPT) $(CONF_CFLAGS) $(EXTRA_CFLAGS)
# the one C++ file: OpenImageIO's plugin (runtime/util/rs_oiio_plugin.cpp),
# BUILD/ringside-oiio.so, loaded when an image file is first read or written
CXX     ?= g++
SAN_CXX := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
CXXFLAGS = -std=c++17 -Wall -Wextra -g -MMD -MP -fPIC $(OPT) $(CONF_CFLAGS) $(if $(filter 1,$(WERROR)),-Werror) \
           $(if $(filter 1,$(SAN)),$(SAN_CXX))
LDLIBS  = $(CONF_LIBS) -lm -lpthread -ldl
LDFLAGS += $(LDFLAGS_SAN)

LIB_SRC := $(wildcard runtime/*.c runtime/*/*.c capture/*.c player/*.c service/*.c) \
           $(filter-out cmd/main.c,$(wildcard cmd/*.c))
MAIN_SRC := cmd/main.c
TEST_SRC := $(wildcard tests/test_*.c)
TEST_BIN := $(patsubst tests/%.c,$(BUILD)/tests/%,$(TEST_SRC))

LIB_OBJ  := $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC))
OIIO_PLUGIN := $(if $(filter oiio,$(CONF_BACKENDS)),$(BUILD)/ringside-oiio.so)
# the announcer's clips, embedded in the binary (runtime/audio/au_voice_data.S)
VOICE_OBJ := $(BUILD)/obj/runtime/audio/au_voice_data.o
LIB_OBJ  += $(VOICE_OBJ)
MAIN_OBJ := $(patsubst %.c,$(BUILD)/obj/%.o,$(MAIN_SRC))

# lower layers never include higher ones (docs/architecture.md, Layers);
# make test runs the same check as tests/test_layers.sh, planted violations too
check-layers:
	@tools/check-layers.sh
	@tools/check-length.sh

.PHONY: check-layers all test test-service web asan asan-all debug demo bench install uninstall clean help deps demo-replays fuzz fuzz-run man
.DEFAULT_GOAL := all
# keep test objects (they are intermediates of a pattern chain) between builds
.SECONDARY:

all: $(BUILD)/ringside $(OIIO_PLUGIN)

# --- dependencies: stamped per group, so a second run is a file compare ---
$(STAMPS)/build: tools/deps.sh
	@tools/deps.sh build
$(STAMPS)/test: tools/deps.sh
	@tools/deps.sh test
$(STAMPS)/service: tools/deps.sh
	@tools/deps.sh service
$(STAMPS)/man: tools/deps.sh
	@tools/deps.sh man
deps: $(STAMPS)/build $(STAMPS)/test

$(BUILD)/config.mk: tools/configure.sh $(STAMPS)/build
	@mkdir -p $(BUILD)
	@RS_ONLY='$(ONLY)' tools/configure.sh > $@.tmp && mv $@.tmp $@

# --- build ---
$(BUILD)/obj/%.o: %.c $(BUILD)/config.mk $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/obj/%.o: %.cpp $(BUILD)/config.mk $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -c $< -o $@

$(VOICE_OBJ): runtime/audio/au_voice_data.S $(wildcard runtime/audio/voice/*.wav) $(BUILD)/config.mk $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Wa,-I,$(CURDIR) -c $< -o $@

$(BUILD)/libringside.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

# the plugin is order-only: whatever runs the program finds it built
$(BUILD)/ringside: $(MAIN_OBJ) $(BUILD)/libringside.a | $(OIIO_PLUGIN)
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/ringside-oiio.so: $(BUILD)/obj/runtime/util/rs_oiio_plugin.o
	$(CXX) -shared $(LDFLAGS) -o $@ $^ $(CONF_OIIO_LIBS)

$(BUILD)/obj/tests/%.o: tests/%.c $(BUILD)/config.mk $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -DRS_SOURCE_DIR='"$(CURDIR)"' -c $< -o $@

$(BUILD)/tests/%: $(BUILD)/obj/tests/%.o $(BUILD)/obj/tests/t.o $(BUILD)/obj/tests/t_render.o $(BUILD)/libringside.a | $(OIIO_PLUGIN)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

# simhash: the simulation alone, at -O0 and at -O2, to prove both give the
# same per-tick hashes (tests/test_replay.sh)
SIM_SRC := $(wildcard runtime/game/*.c runtime/replay/*.c) runtime/util/rs_err.c runtime/util/rs_file.c \
           runtime/util/rs_hash.c tests/simhash.c
$(BUILD)/tests/simhash-O0 $(BUILD)/tests/simhash-O2: $(SIM_SRC) $(wildcard runtime/game/*.h runtime/replay/*.h) $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(filter-out -O% -MMD -MP,$(CFLAGS)) $(subst simhash-,-,$(notdir $@)) $(LDFLAGS) -o $@ $(SIM_SRC) -lm

# libFuzzer targets, one for each parser of outside input (docs/testing.md,
# "Fuzzing"; tests/test_fuzz.sh runs each briefly in make test).  Objects
# are built once under build/fuzz/obj (clang, ASan + UBSan + coverage) and
# shared; no FFmpeg, GL or database code is built in (the libraries'
# fallbacks stand in), libmicrohttpd is, for the HTTP layer.
FUZZ_SECONDS ?= 600
FUZZ_TARGETS := replay wire seg stage config y4m http upload
FUZZ_CFLAGS := -std=c11 -D_POSIX_C_SOURCE=200809L -g -O1 -ffp-contract=off -fsanitize=fuzzer-no-link,address,undefined \
               -fno-sanitize-recover=undefined \
               -DRS_HAVE_MHD=1 $(shell pkg-config --cflags libmicrohttpd 2>/dev/null) -MMD -MP
FUZZ_UTIL := runtime/util/rs_err.c runtime/util/rs_file.c runtime/util/rs_hash.c
FUZZ_SRC_replay := $(filter-out tests/simhash.c,$(SIM_SRC))
FUZZ_SRC_wire := service/svc_wire.c
# what capture/cap.c's size checks (svc_config_finish, uploads) bring along
FUZZ_CAPTURE := capture/cap.c capture/cap_cpu.c capture/cap_scale.c capture/cap_sink.c capture/cap_writer.c \
                capture/cap_out.c capture/cap_sink_images.c capture/cap_sink_y4m.c capture/cap_enc.c \
                runtime/gl/rgl.c runtime/render/r_shader.c runtime/util/rs_progress.c runtime/util/rs_log.c \
                runtime/util/rs_oiio_load.c runtime/util/rs_out.c
FUZZ_SRC_seg := capture/cap_seg.c $(FUZZ_UTIL)
FUZZ_SRC_config := service/svc_config.c $(FUZZ_CAPTURE) $(FUZZ_UTIL)
# the HTTP layer's files and what they call (the queue stores' fallbacks)
FUZZ_SERVICE := service/svc_http_gate.c service/svc_http_routes.c service/svc_http_reply.c service/svc_http_guard.c \
                service/svc_http_jobs.c service/svc_http_ops.c service/svc_http_recv.c service/svc_http_stream.c \
                service/svc_http_events.c \
                service/svc_auth.c capture/cap_hls.c \
                service/svc_upload.c service/svc_encode.c service/svc_json.c service/svc_log.c service/svc_store.c \
                service/svc_store_pg.c service/svc_store_sqlite.c service/svc_files.c service/svc_keep.c \
                service/svc_queue_view.c \
                service/svc_wire.c runtime/replay/rp.c $(wildcard runtime/game/*.c) runtime/render/r_quality.c \
                $(FUZZ_CAPTURE) $(FUZZ_UTIL)
FUZZ_SRC_http := $(FUZZ_SERVICE)
FUZZ_LIBS_http := -lmicrohttpd
FUZZ_SRC_upload := $(FUZZ_SERVICE) service/svc_config.c
FUZZ_LIBS_upload := -lmicrohttpd
FUZZ_SRC_y4m := player/mv_src.c player/mv_y4m.c player/mv_ffmpeg.c $(FUZZ_UTIL)
FUZZ_SRC_stage := runtime/render/r_stage.c $(wildcard runtime/game/*.c) $(FUZZ_UTIL)
FUZZ_LIBS := -lm -lpthread -ldl
ifneq ($(SKIP_CONFIG),1)
# objects depend on the flags, as the main build's do
$(shell mkdir -p build/fuzz && (echo '$(FUZZ_CFLAGS)' | cmp -s - build/fuzz/flags || echo '$(FUZZ_CFLAGS)' > build/fuzz/flags))
endif
fuzz: $(patsubst %,build/fuzz/fuzz_%,$(FUZZ_TARGETS))
build/fuzz/obj/%.o: %.c build/fuzz/flags
	@mkdir -p $(dir $@)
	clang $(FUZZ_CFLAGS) -c $< -o $@
define FUZZ_RULE
build/fuzz/fuzz_$(1): build/fuzz/obj/tests/fuzz_$(1).o $(patsubst %.c,build/fuzz/obj/%.o,$(FUZZ_SRC_$(1)))
	clang -fsanitize=fuzzer,address,undefined -o $$@ $$^ $(FUZZ_LIBS_$(1)) $(FUZZ_LIBS)
endef
$(foreach t,$(FUZZ_TARGETS),$(eval $(call FUZZ_RULE,$(t))))
# make fuzz-run-NAME FUZZ_SECONDS=3600: one target on its seeds, new inputs
# in build/fuzz/corpus-NAME (fuzz-run: the replay reader)
FUZZ_SEEDS_replay := demos/*.rsr tests/golden/dojo-format1.rsr
FUZZ_MAXLEN_replay := 65536
FUZZ_SEEDS_stage := stages/*.stage tests/fuzz/stage/*
fuzz-run: fuzz-run-replay
fuzz-run-%: build/fuzz/fuzz_%
	@mkdir -p build/fuzz/corpus-$*
	cp $(or $(FUZZ_SEEDS_$*),tests/fuzz/$*/*) build/fuzz/corpus-$*/
	build/fuzz/fuzz_$* -max_total_time=$(FUZZ_SECONDS) -max_len=$(or $(FUZZ_MAXLEN_$*),4096) -print_final_stats=1 \
	    build/fuzz/corpus-$*

# the same with clang (tools/deps.sh test installs it, before this is built):
# a second compiler must agree too
SIMHASH_CLANG := $(BUILD)/tests/simhash-clang
$(BUILD)/tests/simhash-clang: $(SIM_SRC) $(wildcard runtime/game/*.h runtime/replay/*.h) | $(STAMPS)/test
	@mkdir -p $(dir $@)
	clang -std=c11 -D_POSIX_C_SOURCE=200809L -O2 -ffp-contract=off -o $@ $(SIM_SRC) -lm

# --- tests ---
test: $(STAMPS)/test $(STAMPS)/man $(BUILD)/ringside $(TEST_BIN) $(BUILD)/tests/simhash-O0 $(BUILD)/tests/simhash-O2 $(SIMHASH_CLANG)
	@$(if $(TIER),RS_TIER=$(TIER) )tests/run.sh $(BUILD) $(T)

# hls.js from npm (service/web/package-lock.json): the dashboard's player of
# live streams in browsers without HLS of their own; the daemon serves it as
# /hls.js (docs/service.md, "Dashboard").  Needs the npm registry once.
HLS_JS := service/web/node_modules/hls.js/dist/hls.min.js
web: $(HLS_JS)
$(HLS_JS): service/web/package.json service/web/package-lock.json | $(STAMPS)/service
	cd service/web && npm ci --no-audit --no-fund --loglevel=error
	@touch $@

# the service end to end: real HTTP, SQLite, a PostgreSQL server started by
# the tests, headless Chromium on the dashboard (docs/service.md)
test-service: $(STAMPS)/test $(STAMPS)/service $(BUILD)/ringside $(BUILD)/tests/test_svc_store $(BUILD)/tests/simhash-O2 $(HLS_JS)
	@RS_SUITE=service tests/run.sh $(BUILD) $(T)

# the sanitizers on what finds our memory bugs (tests/asan.tier, docs/testing.md);
# asan-all: on every suite
asan:
	@$(MAKE) --no-print-directory BUILD=build-asan SAN=1 TIER=asan test
asan-all:
	@$(MAKE) --no-print-directory BUILD=build-asan SAN=1 test

debug:
	@$(MAKE) --no-print-directory BUILD=build-debug DEBUG=1 all

# --- the main job and benchmarks ---
demo: $(BUILD)/ringside
	@mkdir -p out
	$(BUILD)/ringside replay verify demos/dojo.rsr
	$(BUILD)/ringside render demos/dojo.rsr -y -o out/demo.mp4
	@echo "demo: out/demo.mp4, demos/dojo.rsr rendered headless (quality standard: 640x360 drawn and written, H.264, 60 fps, AAC)"

bench: $(BUILD)/ringside
	@mkdir -p out
	$(BUILD)/ringside bench platform -y --csv out/bench-platform.csv
	$(BUILD)/ringside bench sim -y --csv out/bench-sim.csv
	$(BUILD)/ringside bench capture -y --csv out/bench-capture.csv --chart out/bench-capture.png
	$(BUILD)/ringside bench upload -y --csv out/bench-upload.csv
	$(BUILD)/ringside bench audio -y --csv out/bench-audio.csv
	$(BUILD)/ringside bench quality -y --csv out/bench-quality.csv --chart out/bench-quality.png

# The bundled demo replays (demos/*.rsr), made by the CPU recorder.  The
# same commands must reproduce them byte for byte (tests/test_replay.sh).
DEMO_REPLAYS := dojo:1 harbor:7 temple:23 shallows:31 snowfield:37 mistvale:41 plaza:43 quarry:47
demo-replays: $(BUILD)/ringside
	@for d in $(DEMO_REPLAYS); do \
	    stage=$${d%%:*} seed=$${d##*:}; \
	    $(BUILD)/ringside record --ai --quiet --stage $$stage --seed $$seed -y -o demos/$$stage.rsr || exit 1; \
	done

# --- what a system package ships (README, Installing) ---
# The manual pages, the completion and the example config are made from the
# binary's own --help (tools/man.sh says why), so they are rebuilt with it.
MAN_STAMP := $(BUILD)/man/.made
man: $(MAN_STAMP) $(BUILD)/dist/ringside.bash $(BUILD)/dist/ringside.conf.example
$(MAN_STAMP): $(BUILD)/ringside tools/man.sh $(STAMPS)/man
	@rm -rf $(BUILD)/man
	tools/man.sh $(BUILD)/ringside $(BUILD)/man
	@for f in $(BUILD)/man/*.[15]; do w=$$(groff -man -Tutf8 -ww -z $$f 2>&1; mandoc -Tlint -W warning $$f 2>&1); \
	    [ -z "$$w" ] || { echo "$$f: $$w" >&2; exit 1; }; done
	@touch $@
$(BUILD)/dist/ringside.bash: $(BUILD)/ringside tools/completion.sh
	@mkdir -p $(dir $@)
	tools/completion.sh $(BUILD)/ringside > $@.tmp && mv $@.tmp $@
$(BUILD)/dist/ringside.conf.example: $(BUILD)/ringside tools/example-conf.sh
	@mkdir -p $(dir $@)
	tools/example-conf.sh $(BUILD)/ringside > $@.tmp && mv $@.tmp $@

# --- install ---
# Where the files go under PREFIX (and DESTDIR, for packagers):
#   bin/ringside; lib/ringside/ringside-oiio.so (OpenImageIO, loaded when used);
#   share/ringside/{shaders,demos,stages,service}: what it reads at run time
#   share/man/man1, man5; share/bash-completion/completions/ringside
#   lib/systemd/system/ringside.service (SYSTEMD_UNIT_DIR: /lib/systemd/system for PREFIX=/usr)
#   share/doc/ringside: README.md, docs/, ringside.conf.example
#   SYSCONFDIR/ringside/ringside.conf (/etc for PREFIX=/usr, else PREFIX/etc): the
#   example, as the unit's config file, only where there is none (never over
#   an operator's); uninstall removes it only while it is still the example
DATA_DIR   = $(DESTDIR)$(PREFIX)/share/ringside
DOC_DIR    = $(DESTDIR)$(PREFIX)/share/doc/ringside
MAN_DIR    = $(DESTDIR)$(PREFIX)/share/man
COMPL_DIR  = $(DESTDIR)$(PREFIX)/share/bash-completion/completions
SYSTEMD_UNIT_DIR ?= $(PREFIX)/lib/systemd/system
SYSCONFDIR ?= $(if $(filter /usr,$(PREFIX)),/etc,$(PREFIX)/etc)
CONF       = $(DESTDIR)$(SYSCONFDIR)/ringside/ringside.conf
install: $(BUILD)/ringside man
	install -d $(DESTDIR)$(PREFIX)/bin $(DATA_DIR)/shaders $(DATA_DIR)/demos $(DATA_DIR)/stages $(DATA_DIR)/service \
	    $(MAN_DIR)/man1 $(MAN_DIR)/man5 $(COMPL_DIR) $(DESTDIR)$(SYSTEMD_UNIT_DIR) $(DOC_DIR)/docs \
	    $(DESTDIR)$(SYSCONFDIR)/ringside
	install -m 755 $(BUILD)/ringside $(DESTDIR)$(PREFIX)/bin/ringside
	$(if $(OIIO_PLUGIN),install -d $(DESTDIR)$(PREFIX)/lib/ringside && install -m 644 $(OIIO_PLUGIN) $(DESTDIR)$(PREFIX)/lib/ringside/)
	install -m 644 shaders/* $(DATA_DIR)/shaders/
	install -m 644 demos/*.rsr $(DATA_DIR)/demos/
	install -m 644 stages/*.stage $(DATA_DIR)/stages/
	install -m 644 service/dashboard.html $(DATA_DIR)/service/
	@if [ -f $(HLS_JS) ]; then echo "install -m 644 $(HLS_JS) $(DATA_DIR)/service/hls.min.js"; \
	    install -m 644 $(HLS_JS) $(DATA_DIR)/service/hls.min.js; \
	    else echo "install: no $(HLS_JS) ('make web' fetches it): the dashboard plays live streams only where the browser plays HLS itself"; fi
	install -m 644 $(BUILD)/man/*.1 $(MAN_DIR)/man1/
	install -m 644 $(BUILD)/man/*.5 $(MAN_DIR)/man5/
	install -m 644 $(BUILD)/dist/ringside.bash $(COMPL_DIR)/ringside
	sed -e 's|@BINDIR@|$(PREFIX)/bin|g' -e 's|@SYSCONFDIR@|$(SYSCONFDIR)|g' dist/ringside.service > $(DESTDIR)$(SYSTEMD_UNIT_DIR)/ringside.service
	chmod 644 $(DESTDIR)$(SYSTEMD_UNIT_DIR)/ringside.service
	install -m 644 README.md $(BUILD)/dist/ringside.conf.example $(DOC_DIR)/
	install -m 644 docs/*.md docs/*.png $(DOC_DIR)/docs/
	@if [ -e $(CONF) ]; then echo "install: $(CONF) exists: left as it is"; \
	    else echo "install -m 644 $(BUILD)/dist/ringside.conf.example $(CONF)"; \
	    install -m 644 $(BUILD)/dist/ringside.conf.example $(CONF); fi

uninstall:
	rm -f $(DESTDIR)$(PREFIX)/bin/ringside
	rm -rf $(DESTDIR)$(PREFIX)/lib/ringside
	rm -rf $(DESTDIR)$(PREFIX)/share/ringside $(DESTDIR)$(PREFIX)/share/doc/ringside
	rm -f $(MAN_DIR)/man1/ringside.1 $(MAN_DIR)/man1/ringside-*.1 $(MAN_DIR)/man5/ringside.conf.5
	rm -f $(COMPL_DIR)/ringside $(DESTDIR)$(SYSTEMD_UNIT_DIR)/ringside.service
	@if [ -e $(CONF) ] && ! grep -qv '^#\|^$$' $(CONF); then rm -f $(CONF); rmdir $(DESTDIR)$(SYSCONFDIR)/ringside 2>/dev/null; \
	    elif [ -e $(CONF) ]; then echo "uninstall: $(CONF) has settings: left as it is"; fi; true

clean:
	rm -rf build build-asan build-debug out

help:
	@sed -n '1,/^$$/p' Makefile | sed 's/^# \{0,1\}//'

-include $(shell find $(BUILD)/obj build/fuzz/obj -name '*.d' 2>/dev/null)
