# Sourced by the Mitsuba checks (validate_reference.sh, validate_shadows.sh): from the
# repository root, checks that $PYTHON (default python3) has Mitsuba 3, NumPy and Pillow, and
# sets `forest` to $FOREST or a freshly built release binary.
PYTHON=${PYTHON:-python3}
"$PYTHON" -c "import mitsuba, numpy, PIL" 2>/dev/null || {
  echo "needs Mitsuba 3: pip install mitsuba numpy pillow (then PYTHON=that/python $0)" >&2
  exit 1
}
# FOREST: a forest binary to use instead of building one.
if [ -z "${FOREST:-}" ]; then
  cargo build --release --locked -p forest-cli
  FOREST=${CARGO_TARGET_DIR:-target}/release/forest
fi
forest=$FOREST
