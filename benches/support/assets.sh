# Sourced by the benchmark scripts, from the repository's root: `assets`, the shared assets' folder (the script
# stops with a message where it is missing), and `target`, where cargo builds.
assets=../shared/assets
if [ ! -d "$assets" ]; then
  echo "skipped: the shared assets are not in $assets"
  exit 0
fi
target=${CARGO_TARGET_DIR:-target}
