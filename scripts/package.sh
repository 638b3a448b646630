#!/usr/bin/env bash
# The Debian package (docs/daemon.md "The Debian package"; cmake/Packaging.cmake).
#   scripts/package.sh           install what is missing, build the release preset, run
#                                `cpack -G DEB` in it: build/release/hapticd_<version>_<arch>.deb
#   scripts/package.sh --check   the same, then check the package end to end (what CI runs, as
#                                root on Debian 12; it needs no network beyond apt for missing
#                                build dependencies):
#     1. its files, modes and owners and its control members equal packaging/debian/contents.txt;
#        Version is packaging/debian/changelog's, Depends was computed (dpkg-shlibdeps);
#     2. lintian reports no error and no warning (the accepted ones are overridden, with the reason,
#        in packaging/debian/lintian-overrides);
#     3. `apt-get install ./hapticd_*.deb` installs it: `systemd-analyze verify` says nothing about
#        the installed unit, /usr/bin/hapticd --help and hapticctl --help work, the installed config
#        passes --check-config, the group exists, the conffile is registered, the unit is neither
#        enabled nor started, Debian's python3 imports the Python client;
#     4. after `systemctl enable hapticd` (as an administrator would), `apt-get remove --purge
#        hapticd` leaves none of its files, folders, enable links, systemd state or bytecode.
#   The check refuses to run when hapticd is installed already, purges what it installed when a
#   step fails, and deletes the group hapticd afterwards when it did not exist before (the package
#   leaves the group on purge, as Debian does).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

check=0
case "${1:-}" in
  "") ;;
  --check) check=1 ;;
  *) echo "usage: $0 [--check]" >&2; exit 2 ;;
esac

fail() { echo "package: FAIL: $*" >&2; exit 1; }
step() { echo "== package: $*"; }

scripts/install-deps.sh
step "build (release preset) and cpack -G DEB"
cmake --preset release >/dev/null
cmake --build --preset release
rm -f build/release/hapticd_*.deb
(cd build/release && cpack -G DEB) || fail "cpack -G DEB"
debs=(build/release/hapticd_*.deb)
[[ ${#debs[@]} -eq 1 && -f ${debs[0]} ]] || fail "expected one build/release/hapticd_*.deb, found: ${debs[*]}"
deb="$root/${debs[0]}"
echo "package: $deb"
[[ $check -eq 1 ]] || exit 0

[[ $(id -u) -eq 0 ]] || fail "--check installs the package: run it as root"
export DEBIAN_FRONTEND=noninteractive
# dpkg's state of hapticd: "not-installed" when dpkg has no trace of it
hapticd_state() { dpkg-query -W -f='${db:Status-Status}' hapticd 2>/dev/null || echo not-installed; }
[[ $(hapticd_state) == not-installed ]] ||
  fail "hapticd is $(hapticd_state) already; --check installs and purges it: purge it first"
work=$(mktemp -d)
installed_by_us=0
group_before=0
getent group hapticd >/dev/null && group_before=1
cleanup() {
  if [[ $installed_by_us -eq 1 ]]; then
    echo "package: cleaning up: purging hapticd"
    apt-get remove --purge -y -qq hapticd >/dev/null 2>&1 || true
  fi
  if [[ $group_before -eq 0 ]] && getent group hapticd >/dev/null; then
    groupdel hapticd || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT

# --- 1. contents
step "contents against packaging/debian/contents.txt"
{
  dpkg-deb --ctrl-tarfile "$deb" | tar -tvf - |
    awk '$6 != "./" { sub(/^\.\//, "DEBIAN/", $6); print $6, $1, $2 }'
  dpkg-deb --fsys-tarfile "$deb" | tar -tvf - | awk '{ print $6, $1, $2 }'
} | LC_ALL=C sort > "$work/contents"
grep -v -e '^#' -e '^$' packaging/debian/contents.txt | LC_ALL=C sort > "$work/expected"
if ! diff -u "$work/expected" "$work/contents"; then
  fail "the package's contents differ from packaging/debian/contents.txt (- expected, + built)"
fi
echo "package: $(wc -l < "$work/contents") entries as expected"
version=$(dpkg-deb -f "$deb" Version)
changelog_version=$(dpkg-parsechangelog -l packaging/debian/changelog -S Version)
[[ $version == "$changelog_version" ]] ||
  fail "package version $version, packaging/debian/changelog's latest entry $changelog_version"
depends=$(dpkg-deb -f "$deb" Depends)
[[ $depends == *libc6* ]] || fail "Depends was not computed by dpkg-shlibdeps: '$depends'"
echo "package: Version $version; Depends: $depends"

# --- 2. lintian
step "lintian"
# the overridden tags with their reasons, for the log (as root lintian says it should not run as
# root; CI runs as root)
lintian --show-overrides "$deb" 2>&1 | grep -v 'running with root privileges' || true
lintian --fail-on error,warning "$deb" >/dev/null 2>&1 ||
  fail "lintian reports errors or warnings (above; an accepted one goes in packaging/debian/lintian-overrides with its reason)"
echo "package: lintian: no errors, no warnings that are not overridden"

# --- 3. install and check the installed package
step "apt-get install ./$(basename "$deb")"
installed_by_us=1
(cd "$(dirname "$deb")" && apt-get install -y -qq --no-install-recommends "./$(basename "$deb")") ||
  fail "apt-get install"
[[ $(hapticd_state) == installed ]] || fail "hapticd is $(hapticd_state), not installed"
unit=/lib/systemd/system/hapticd.service
[[ -f $unit ]] || fail "no $unit"
grep -qx 'ExecStart=/usr/bin/hapticd --config /etc/hapticd/hapticd.toml' "$unit" ||
  fail "$unit: ExecStart is not /usr/bin/hapticd --config /etc/hapticd/hapticd.toml"
verify=$(cd "$work" && systemd-analyze verify "$unit" 2>&1) || fail "systemd-analyze verify $unit: $verify"
[[ -z $verify ]] || fail "systemd-analyze verify $unit said: $verify"
echo "package: systemd-analyze verify $unit: no warnings"
/usr/bin/hapticd --help >"$work/help" 2>&1 || fail "/usr/bin/hapticd --help: $(cat "$work/help")"
grep -q -- '--config' "$work/help" || fail "/usr/bin/hapticd --help does not list --config"
/usr/bin/hapticctl --help >/dev/null 2>&1 || fail "/usr/bin/hapticctl --help"
/usr/bin/hapticd --config /etc/hapticd/hapticd.toml --check-config >"$work/cc" 2>&1 ||
  fail "/usr/bin/hapticd --check-config on /etc/hapticd/hapticd.toml: $(cat "$work/cc")"
echo "package: /usr/bin/hapticd --help, hapticctl --help, --check-config /etc/hapticd/hapticd.toml: ok"
getent group hapticd >/dev/null || fail "postinst did not create the group hapticd"
dpkg-query -W -f='${Conffiles}' hapticd | grep -q '/etc/hapticd/hapticd.toml' ||
  fail "/etc/hapticd/hapticd.toml is not a conffile"
if compgen -G '/etc/systemd/system/*.wants/hapticd.service' >/dev/null; then
  fail "the unit was enabled: $(ls /etc/systemd/system/*.wants/hapticd.service)"
fi
if [[ -d /run/systemd/system ]] && systemctl is-active --quiet hapticd.service; then
  fail "the service was started"
fi
if [[ -x /usr/bin/python3 ]]; then
  # Debian's python3 (not another one first on PATH); as root it writes
  # __pycache__/hapticd_client.*.pyc next to the module, which the prerm must remove
  (cd "$work" && env -u PYTHONDONTWRITEBYTECODE /usr/bin/python3 -c 'import hapticd_client') ||
    fail "/usr/bin/python3 cannot import hapticd_client"
  compgen -G '/usr/lib/python3/dist-packages/__pycache__/hapticd_client.*.pyc' >/dev/null ||
    fail "importing hapticd_client as root wrote no bytecode (the purge check below needs it)"
fi
echo "package: group hapticd, conffile, unit not enabled nor started, python3 imports hapticd_client: ok"
# the administrator enables the unit (docs/daemon.md); purge must remove the links
systemctl enable hapticd.service >/dev/null 2>&1 || fail "systemctl enable hapticd.service"
[[ -L /etc/systemd/system/multi-user.target.wants/hapticd.service ]] ||
  fail "systemctl enable made no multi-user.target.wants link"

# --- 4. remove, nothing left
step "apt-get remove --purge hapticd"
apt-get remove --purge -y -qq hapticd || fail "apt-get remove --purge hapticd"
installed_by_us=0
[[ $(hapticd_state) == not-installed ]] || fail "after the purge hapticd is $(hapticd_state)"
left=()
while read -r path _ _; do
  path=${path#.}
  [[ -z $path || $path == / || $path == */ ]] && continue  # folders: those of its own below
  [[ -e $path || -L $path ]] && left+=("$path")
done < <(grep -v -e '^#' -e '^$' -e '^DEBIAN/' packaging/debian/contents.txt)
for path in /etc/hapticd /usr/share/doc/hapticd /usr/share/hapticd; do
  [[ -e $path || -L $path ]] && left+=("$path")
done
# enable links, deb-systemd-helper's state, Python's bytecode of the client
while read -r path; do
  left+=("$path")
done < <(find /etc/systemd /var/lib/systemd/deb-systemd-helper-enabled \
              /var/lib/systemd/deb-systemd-helper-masked /usr/lib/python3/dist-packages/__pycache__ \
              -name 'hapticd*' 2>/dev/null)
[[ ${#left[@]} -eq 0 ]] || fail "left after purge: ${left[*]}"
echo "package: purged, nothing of it left"
echo "== package: check passed ($deb)"
