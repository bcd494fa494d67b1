#!/usr/bin/env bash
# System packages some tests drive for real (tmux for the terminal walkthrough test; chromium
# renders the evaluation report headless in tests/evaluation_output/test_report_browser.py;
# socat makes the pty pair of tests/bindings/test_dispenser_end_to_end.py; graphviz's dot lays out
# `opspec show --format svg|html`, tests/validate/test_show_package_picture.py).
# Installed only when missing and only when we may (root or passwordless sudo); tests that
# need a missing tool skip with a message naming this script.
set -uo pipefail
need=()
command -v tmux >/dev/null 2>&1 || need+=(tmux)
command -v socat >/dev/null 2>&1 || need+=(socat)
command -v dot >/dev/null 2>&1 || need+=(graphviz)
command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 \
  || command -v google-chrome >/dev/null 2>&1 || need+=(chromium)
[ ${#need[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -eq 0 ]; then sudo=""; elif sudo -n true 2>/dev/null; then sudo="sudo -n"; else
  echo "system-deps: missing ${need[*]} and no root: the tests that need them will be skipped" >&2
  exit 0
fi
if command -v apt-get >/dev/null 2>&1; then
  $sudo apt-get update -qq >/dev/null 2>&1 || true
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${need[@]}" >/dev/null 2>&1 \
    || echo "system-deps: could not install ${need[*]}: the tests that need them will be skipped" >&2
fi
exit 0
