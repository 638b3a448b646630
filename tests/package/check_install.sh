#!/bin/sh
# check_install.sh CMAKE BUILD_DIR SOURCE_DIR VERSION: see tests/package/CMakeLists.txt.
set -eu
cmake=$1 build=$2 source=$3 version=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# files and modes installed under DESTDIR $1 ("./PATH MODE", sorted)
list_files() {
  (cd "$1" && find . ! -type d -printf './%P %M\n') | LC_ALL=C sort
}

# --- prefix /usr: the package's layout
DESTDIR="$work/usr" "$cmake" --install "$build" --prefix /usr >"$work/install-usr.log" 2>&1 ||
  { cat "$work/install-usr.log"; echo "FAIL: cmake --install --prefix /usr"; exit 1; }
list_files "$work/usr" >"$work/installed"
# contents.txt: "./PATH MODE OWNER" for the data (folders end in /), "DEBIAN/..." for control members
grep -v -e '^#' -e '^$' -e '^DEBIAN/' "$source/packaging/debian/contents.txt" |
  awk '$1 !~ /\/$/ { print $1, $2 }' | LC_ALL=C sort >"$work/expected"
if ! diff -u "$work/expected" "$work/installed"; then
  fail "cmake --install --prefix /usr differs from packaging/debian/contents.txt (- expected, + installed)"
fi
unit="$work/usr/lib/systemd/system/hapticd.service"
grep -qx 'ExecStart=/usr/bin/hapticd --config /etc/hapticd/hapticd.toml' "$unit" ||
  fail "prefix /usr: $(grep '^ExecStart=' "$unit")"
grep -qx 'Documentation=file:///usr/share/doc/hapticd/daemon.md' "$unit" ||
  fail "prefix /usr: $(grep '^Documentation=' "$unit")"
if grep -n '@[A-Z_]*@' "$unit"; then fail "prefix /usr: the unit has unreplaced placeholders"; fi

# --- any other prefix: everything under it
p=/opt/hapticd-layout-test
DESTDIR="$work/opt" "$cmake" --install "$build" --prefix "$p" >"$work/install-opt.log" 2>&1 ||
  { cat "$work/install-opt.log"; echo "FAIL: cmake --install --prefix $p"; exit 1; }
outside=$( (cd "$work/opt" && find . ! -type d) | grep -v "^\.$p/" || true)
[ -z "$outside" ] || fail "prefix $p: installed outside it: $outside"
for f in bin/hapticd bin/hapticctl etc/hapticd/hapticd.toml lib/systemd/system/hapticd.service \
         lib/udev/rules.d/70-hapticd.rules lib/sysusers.d/hapticd.conf \
         lib/python3/dist-packages/hapticd_client.py share/doc/hapticd/copyright; do
  [ -f "$work/opt$p/$f" ] || fail "prefix $p: no $f"
done
unit="$work/opt$p/lib/systemd/system/hapticd.service"
grep -qx "ExecStart=$p/bin/hapticd --config $p/etc/hapticd/hapticd.toml" "$unit" ||
  fail "prefix $p: $(grep '^ExecStart=' "$unit")"
grep -qx "Documentation=file://$p/share/doc/hapticd/daemon.md" "$unit" ||
  fail "prefix $p: $(grep '^Documentation=' "$unit")"

# --- the changelog: gzip -9 (lintian), its latest entry is this version
changelog="$work/usr/usr/share/doc/hapticd/changelog.gz"
gzip -t "$changelog" || fail "changelog.gz is not a valid gzip file"
top=$(gzip -dc "$changelog" | head -n 1)
case "$top" in
  "hapticd ($version) "*) ;;
  *) fail "packaging/debian/changelog's latest entry is '$top', the project's version $version" ;;
esac

if [ "$fails" -ne 0 ]; then echo "$fails check(s) failed"; exit 1; fi
echo "install layout: prefix /usr as packaging/debian/contents.txt, prefix $p self-contained, changelog $version"
