# Sourced by the stop tests (stop_signals.sh, stop_curves.sh): sets `launch`, the prefix that
# starts a command with SIGINT at its default. A command started with & by a non-interactive shell
# ignores SIGINT, and pwl leaves an ignored signal ignored. Exits 77 (the tests' skip code) where
# env cannot do it.
if env --default-signal=INT true 2> /dev/null; then
  launch="env --default-signal=INT"
else
  echo "SKIP: this env cannot start a command with SIGINT at its default (coreutils < 8.31)"
  exit 77
fi
