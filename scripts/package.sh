#!/usr/bin/env bash
# Builds the Debian packages (viscera-player, viscera-studio, viscera-samples) with CPack and
# checks them: each one's Section, Depends and files (docs, copyright, changelog, a man page per
# program), that the player depends on no authoring library, lintian with 0 errors; then the
# player and samples packages are extracted into a temporary root and the extracted player
# verifies every sample and runs two of them headless from there. The samples' trust anchor: a
# test build's samples package installs none (its cases are checked against the build's test key,
# --trust, or as a site key in /etc/viscera/trusted-publishers when installed); a
# release-configured one (packaging/samples, a throwaway publisher key) installs that key only.
# Usage: scripts/package.sh   (after scripts/configure.sh; VISCERA_BUILD_DIR as there)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${VISCERA_BUILD_DIR:-build}
JOBS=${VISCERA_JOBS:-$(nproc)}
fail() { echo "package: FAILED: $*" >&2; exit 1; }

# What to undo on exit, newest first: the site key, the installed packages, the temporary root.
root=""
installed=0
site_key=/etc/viscera/trusted-publishers/viscera-samples-test.pub.pem # this script's own file
site_dirs=() # the folders above it that this script made, innermost first
cleanup() {
  remove_site_key
  if ((installed)); then apt-get remove -y -qq viscera-player viscera-studio viscera-samples >/dev/null 2>&1 || true; fi
  if [[ -n "$root" ]]; then rm -rf "$root"; fi
}
trap cleanup EXIT

# The samples' signing key (packaging/publisher_key.cmake): the publisher's given to a release
# build, whose public half the samples package installs; else the build's test key, installed by
# no package: the checks below trust it themselves.
publisher_key() { sed -n 's/^VISCERA_PUBLISHER_KEY:[A-Z]*=//p' "$BUILD_DIR/CMakeCache.txt"; }
test_key="$BUILD_DIR/keys/viscera-samples.pub.pem"
anchors_in() { dpkg-deb -c "$1" | awk '{print $6}' | grep '^\./usr/share/viscera/trusted-publishers/.' || true; }
pub_name() { local k; k=$(basename "$1"); echo "${k%.pem}.pub.pem"; } # KEY.pem -> KEY.pub.pem

# viscera-samples' trust anchors: a test build's installs none, a release build's its publisher's.
check_samples_anchor() {
  local anchors key
  anchors=$(anchors_in "$1")
  key=$(publisher_key)
  if [[ -z "$key" ]]; then
    [[ -z "$anchors" ]] || fail "viscera-samples of a test build installs a trust anchor: $anchors"
    [[ -s "$test_key" ]] || fail "no test key at $test_key (target viscera_sample_key)"
    echo "package: viscera-samples (test build): no trust anchor; a site adds its publisher's key:" \
      "KEY.pub.pem into /etc/viscera/trusted-publishers/ (root, 0644, the folder writable by no one else), or --trust"
  else
    [[ "$anchors" == "./usr/share/viscera/trusted-publishers/$(pub_name "$key")" ]] ||
      fail "viscera-samples of a release build: trust anchors '$anchors', expected its publisher's $(pub_name "$key")"
    echo "package: viscera-samples (release build): trust anchor $anchors"
  fi
}

# The site key, as a site administrator adds one: root-owned, 0644, in a folder root owns and no
# one else may write (those of its folders that are missing are made so, and removed on exit).
install_site_key() {
  local d
  for d in /etc/viscera /etc/viscera/trusted-publishers; do
    [[ -d "$d" ]] && continue
    install -d -o root -g root -m 0755 "$d"
    site_dirs=("$d" "${site_dirs[@]}")
  done
  install -o root -g root -m 0644 "$1" "$site_key"
}
remove_site_key() {
  local d
  rm -f "$site_key"
  for d in "${site_dirs[@]}"; do rmdir "$d" 2>/dev/null || true; done
  site_dirs=()
}

# The installed player, with no site key and no --trust, refuses every sample of a test build.
check_untrusted_refused() {
  local c msg
  for c in /usr/share/viscera/samples/*.vcase; do
    if msg=$(/usr/bin/viscera-player verify "$c" 2>&1); then fail "installed: $c verifies with no site key"; fi
    grep -q "a key this player does not trust" <<<"$msg" || fail "installed: verify $c with no site key: $msg"
  done
}

# The three packages installed on this machine's root with apt (their Depends resolved as a user's
# would be), run from /usr as installed: a test build's samples are refused until the build's test
# key is trusted as a site key (/etc/viscera/trusted-publishers), a release build's verify against
# the key their package installs; with it, every sample verifies (no --trust), the launcher finds
# them and draws its case picker under Xvfb, every program answers --version; then the key and the
# packages are removed again (trap).
check_installed() {
  local p
  export DEBIAN_FRONTEND=noninteractive
  remove_site_key # a copy left by a run that was killed
  apt-get install -y -qq --no-install-recommends "${deb[viscera-player]}" "${deb[viscera-studio]}" \
    "${deb[viscera-samples]}" >"$out/install.log" 2>&1 || { cat "$out/install.log"; fail "apt-get install of the packages"; }
  installed=1
  for p in viscera-player viscera-studio viscera-samples; do
    dpkg-query -W -f='${Status}' "$p" | grep -q "install ok installed" || fail "$p is not installed"
  done
  if [[ -z $(publisher_key) ]]; then
    check_untrusted_refused
    install_site_key "$test_key"
  fi
  check_installed_samples
  remove_site_key
}
check_installed_samples() {
  local c b n
  for c in /usr/share/viscera/samples/*.vcase; do /usr/bin/viscera-player verify "$c" >/dev/null || fail "installed: verify $c"; done
  n=$(/usr/bin/viscera-launcher --list 2>/dev/null | grep -c '^/usr/share/viscera/samples/' || true)
  ((n >= 5)) || fail "the installed launcher lists $n of the 5 samples"
  env -u QT_QPA_PLATFORM xvfb-run -a -s "-screen 0 1280x800x24 -nolisten tcp" \
    /usr/bin/viscera-launcher --screenshot "$out/launcher.png" || fail "the installed launcher did not open under Xvfb"
  [[ -s "$out/launcher.png" ]] || fail "the installed launcher drew no picture"
  for b in viscera-player viscera-console-sim viscera-results viscera-launcher viscera-studio; do
    "/usr/bin/$b" --version >/dev/null || fail "installed $b --version"
  done
  echo "package: installed on this root: $n sample cases in the launcher ($out/launcher.png)$(
    [[ -n $(publisher_key) ]] || echo ", with the test key as a site key; refused without it")"
}

# A release-configured samples package, made as a release makes it (packaging/samples: the studio
# just built exports the samples signed with a throwaway publisher key; nothing is compiled): its
# one trust anchor is that key's .pub.pem, it holds no test key, and its cases verify against it
# with the extracted player and no --trust.
make_release_samples() {
  local dir=$1
  mkdir -p "$dir/key"
  "$BUILD_DIR/studio/cli/viscera-studio" keygen -o "$dir/key/release.pem" >"$dir/log" 2>&1 &&
    cmake -S packaging/samples -B "$dir/build" -G Ninja -DVISCERA_PUBLISHER_KEY="$dir/key/release.pem" \
      -DVISCERA_STUDIO="$(cd "$BUILD_DIR" && pwd)/studio/cli/viscera-studio" >>"$dir/log" 2>&1 &&
    cmake --build "$dir/build" -j"$JOBS" --target all viscera_samples >>"$dir/log" 2>&1 &&
    (cd "$dir/build" && cpack -G DEB -B "$dir/out") >>"$dir/log" 2>&1 ||
    { cat "$dir/log"; fail "making the release-configured samples package (packaging/samples)"; }
}
check_release_samples() {
  local dir=$root/release t0=$SECONDS f anchors c
  make_release_samples "$dir"
  f=$(ls "$dir"/out/viscera-samples_*.deb 2>/dev/null | sed -n 1p)
  [[ -n "$f" ]] || fail "packaging/samples made no viscera-samples package"
  anchors=$(anchors_in "$f")
  [[ "$anchors" == ./usr/share/viscera/trusted-publishers/release.pub.pem ]] ||
    fail "release-configured viscera-samples: trust anchors '$anchors', expected release.pub.pem alone"
  dpkg-deb -x "$f" "$dir/root"
  check_no_test_key "$dir/root"
  cmp -s "$dir/root/usr/share/viscera/trusted-publishers/release.pub.pem" "$dir/key/release.pub.pem" ||
    fail "release-configured viscera-samples: its anchor is not the release key's public half"
  dpkg-deb -x "${deb[viscera-player]}" "$dir/root"
  for c in "$dir"/root/usr/share/viscera/samples/*.vcase; do
    "$dir/root/usr/bin/viscera-player" verify "$c" >/dev/null || fail "release-configured viscera-samples: verify $c"
  done
  mkdir -p "$out/release-check" && cp "$f" "$out/release-check/" # to inspect; its key is gone with $root
  echo "package: release-configured viscera-samples: trust anchor $anchors (the release key's), no test key," \
    "its cases verify against it ($((SECONDS - t0)) s; $out/release-check/$(basename "$f"))"
}
# No test key in an extracted package: no .pem but the release key's, not the test key's text.
check_no_test_key() {
  local pems body
  pems=$(cd "$1" && find . -name '*.pem' | sort)
  [[ "$pems" == ./usr/share/viscera/trusted-publishers/release.pub.pem ]] ||
    fail "release-configured viscera-samples: key files '$pems'"
  [[ -s "$test_key" ]] || return 0 # a release build has no test key
  body=$(sed -n 2p "$test_key")
  if grep -rlF -- "$body" "$1"; then fail "release-configured viscera-samples holds the test key"; fi
}

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
check_samples_anchor "${deb[viscera-samples]}"
trust=() # the test key, where the samples package installs no anchor
[[ -n $(publisher_key) ]] || trust=(--trust "$test_key")
root=$(mktemp -d)
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
for c in "${samples[@]}"; do "$player" verify "$c" "${trust[@]}"; done
"$player" run "$root/usr/share/viscera/samples/tissue-slab.vcase" "${trust[@]}" --headless --frames 60 \
  --report "$root/slab.json" | grep -E '^(case|status)'
"$player" run "$root/usr/share/viscera/samples/liver.vcase" "${trust[@]}" --headless --frames 120 \
  --device scripted:press --report "$root/liver.json" --plots "$root/plots" | grep -E '^(case|status|tools|plots)'
[[ -s "$root/plots/session.html" ]] || fail "the extracted player wrote no plots"

# Root only (set VISCERA_PACKAGE_INSTALL=0 to skip on a machine whose /usr and /etc must stay
# untouched).
if [[ $(id -u) -eq 0 && ${VISCERA_PACKAGE_INSTALL:-1} != 0 ]]; then check_installed; fi
check_release_samples

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
