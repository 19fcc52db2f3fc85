#!/usr/bin/env bash
# Builds the Debian packages (viscera-player, viscera-studio, viscera-samples) with CPack and
# checks them: each one's Section, Depends and files (docs, copyright, changelog, a man page per
# program), that the player depends on no authoring library, lintian with 0 errors; then the
# player and samples packages are extracted into a temporary root and the extracted player
# verifies every sample and runs two of them headless from there.
# Usage: scripts/package.sh   (after scripts/configure.sh; VISCERA_BUILD_DIR as there)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${VISCERA_BUILD_DIR:-build}
JOBS=${VISCERA_JOBS:-$(nproc)}
fail() { echo "package: FAILED: $*" >&2; exit 1; }

cmake --build "$BUILD_DIR" -j"$JOBS" --target all viscera_samples
out="$(cd "$BUILD_DIR" && pwd)/packages"
rm -rf "$out"
mkdir -p "$out"
(cd "$BUILD_DIR" && cpack -G DEB -B "$out" >"$out/cpack.log" 2>&1) || { cat "$out/cpack.log"; fail "cpack"; }
rm -rf "$out/_CPack_Packages"

declare -A deb
for p in viscera-player viscera-studio viscera-samples; do
  f=$(ls "$out"/${p}_*.deb 2>/dev/null | sed -n 1p)
  [[ -n "$f" ]] || fail "cpack made no $p package"
  deb[$p]=$f
done

summaries=()
for p in viscera-player viscera-studio viscera-samples; do
  f=${deb[$p]}
  section=$(dpkg-deb -f "$f" Section)
  [[ "$section" == science ]] || fail "$p: Section is '$section', not science"
  summary=$(dpkg-deb -f "$f" Description | sed -n 1p) # sed reads it all: head could SIGPIPE dpkg-deb under pipefail
  for s in "${summaries[@]}"; do [[ "$s" != "$summary" ]] || fail "$p: its description is another package's"; done
  summaries+=("$summary")
  files=$(dpkg-deb -c "$f" | awk '{print $6}')
  case $p in # packaging/cpack.cmake's VISCERA_DOCS_<component>: the trainees' guides, not the developer README
    viscera-player) docs="trainee-guide.md console-setup.md vcase-spec.md console-protocol.md" ;;
    viscera-studio) docs="README.md vcase-spec.md console-protocol.md" ;;
    viscera-samples) docs="vcase-spec.md" ;;
  esac
  for d in copyright changelog.gz $docs; do
    grep -qx "./usr/share/doc/$p/$d" <<<"$files" || fail "$p: no /usr/share/doc/$p/$d"
  done
  for b in $(grep '^\./usr/bin/' <<<"$files" | sed 's|^\./usr/bin/||'); do
    grep -qx "./usr/share/man/man1/$b.1.gz" <<<"$files" || fail "$p: /usr/bin/$b has no man page"
  done
  printf '%-16s %8s KiB installed, %8s bytes .deb\n  Depends: %s\n' "$p" "$(dpkg-deb -f "$f" Installed-Size)" \
    "$(stat -c %s "$f")" "$(dpkg-deb -f "$f" Depends)"
done

# The lean player: nothing of the authoring stack in its Depends or in its programs' NEEDED.
authoring='cgal|openvdb|opencv|assimp|qt6widgets|qt6openglwidgets|qt6concurrent|libtbb'
if dpkg-deb -f "${deb[viscera-player]}" Depends | grep -Eiq "$authoring"; then
  fail "viscera-player depends on an authoring library: $(dpkg-deb -f "${deb[viscera-player]}" Depends)"
fi
root=$(mktemp -d)
trap 'rm -rf "$root"' EXIT
dpkg-deb -x "${deb[viscera-player]}" "$root"
dpkg-deb -x "${deb[viscera-samples]}" "$root"
for b in "$root"/usr/bin/*; do
  needed=$(readelf -d "$b") || fail "$(basename "$b"): readelf cannot read it"
  grep -q NEEDED <<<"$needed" || fail "$(basename "$b"): no NEEDED entries (not a dynamic program?)"
  if grep NEEDED <<<"$needed" | grep -Eiq "$authoring"; then fail "$(basename "$b") links an authoring library"; fi
done
[[ -z $(dpkg-deb -c "${deb[viscera-studio]}" | awk '{print $6}' | grep '^\./usr/bin/viscera-player') ]] ||
  fail "viscera-studio ships the player"
samples=("$root"/usr/share/viscera/samples/*.vcase)
((${#samples[@]} >= 5)) || fail "viscera-samples has ${#samples[@]} cases, expected the 5 sample projects"

replays=("$root"/usr/share/viscera/samples/replays/*/*.csv)
((${#replays[@]} >= 3)) || fail "viscera-samples has ${#replays[@]} replays, expected those of projects/*/replays"
[[ -f "$root/usr/share/applications/viscera-launcher.desktop" ]] || fail "viscera-player has no launcher .desktop file"
if command -v desktop-file-validate >/dev/null; then
  desktop-file-validate "$root/usr/share/applications/viscera-launcher.desktop" || fail "viscera-launcher.desktop"
fi

# Every extracted program answers --version with "<name> <version>".
version=$(dpkg-deb -f "${deb[viscera-player]}" Version)
for b in "$root"/usr/bin/*; do
  v=$("$b" --version) || fail "$(basename "$b") --version failed"
  [[ "$v" == "$(basename "$b") $version" ]] || fail "$(basename "$b") --version said '$v'"
done

# The extracted player, from the temporary root: verify every sample, run two headless.
player="$root/usr/bin/viscera-player"
for c in "${samples[@]}"; do "$player" verify "$c"; done
"$player" run "$root/usr/share/viscera/samples/tissue-slab.vcase" --headless --frames 60 --report "$root/slab.json" |
  grep -E '^(case|status)'
"$player" run "$root/usr/share/viscera/samples/liver.vcase" --headless --frames 120 --device scripted:press \
  --report "$root/liver.json" --plots "$root/plots" | grep -E '^(case|status|tools|plots)'
[[ -s "$root/plots/session.html" ]] || fail "the extracted player wrote no plots"

# The three packages installed on this machine's root with apt (their Depends resolved as a user's
# would be), run from /usr as installed: the samples verify against the publisher key the samples
# package installs (no --trust), the launcher finds them and draws its case picker under Xvfb, every
# program answers --version; then removed again. Root only (set VISCERA_PACKAGE_INSTALL=0 to skip
# on a machine whose /usr must stay untouched).
if [[ $(id -u) -eq 0 && ${VISCERA_PACKAGE_INSTALL:-1} != 0 ]]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get install -y -qq --no-install-recommends "${deb[viscera-player]}" "${deb[viscera-studio]}" \
    "${deb[viscera-samples]}" >"$out/install.log" 2>&1 || { cat "$out/install.log"; fail "apt-get install of the packages"; }
  trap 'rm -rf "$root"; apt-get remove -y -qq viscera-player viscera-studio viscera-samples >/dev/null 2>&1 || true' EXIT
  for p in viscera-player viscera-studio viscera-samples; do
    dpkg-query -W -f='${Status}' "$p" | grep -q "install ok installed" || fail "$p is not installed"
  done
  for c in /usr/share/viscera/samples/*.vcase; do /usr/bin/viscera-player verify "$c" >/dev/null || fail "installed: verify $c"; done
  n=$(/usr/bin/viscera-launcher --list 2>/dev/null | grep -c '^/usr/share/viscera/samples/' || true)
  ((n >= 5)) || fail "the installed launcher lists $n of the 5 samples"
  env -u QT_QPA_PLATFORM xvfb-run -a -s "-screen 0 1280x800x24 -nolisten tcp" \
    /usr/bin/viscera-launcher --screenshot "$out/launcher.png" || fail "the installed launcher did not open under Xvfb"
  [[ -s "$out/launcher.png" ]] || fail "the installed launcher drew no picture"
  for b in viscera-player viscera-console-sim viscera-results viscera-launcher viscera-studio; do
    "/usr/bin/$b" --version >/dev/null || fail "installed $b --version"
  done
  echo "package: installed on this root: $n sample cases in the launcher ($out/launcher.png)"
fi

# lintian: 0 errors (warnings are listed).
lint="$out/lintian.txt"
command -v lintian >/dev/null || fail "lintian is not installed (scripts/install-deps.sh installs it)"
rc=0
lintian --tag-display-limit 0 "${deb[@]}" >"$lint" 2>&1 || rc=$?
((rc <= 1)) || { cat "$lint"; fail "lintian did not run (exit $rc)"; }  # 1: it found errors, counted below
cat "$lint"
errors=$(grep -c '^E: ' "$lint" || true)
warnings=$(grep -c '^W: ' "$lint" || true)
echo "package: lintian: $errors errors, $warnings warnings"
((errors == 0)) || fail "lintian reported $errors errors"
echo "package: ok — $(ls "$out"/*.deb | xargs -n1 basename | tr '\n' ' ')"
