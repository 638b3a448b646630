# Install-time part of cmake/Packaging.cmake: the files whose place depends on the prefix given when
# installing (`cmake --install ... --prefix P`, or /usr when cpack builds the Debian package), which
# is known only now, not at configure time. Run by install(SCRIPT) after Packaging.cmake's
# install(CODE) has set HAPTICD_SOURCE_DIR, HAPTICD_STAGE_DIR, HAPTICD_INSTALL_{BINDIR,DOCDIR,
# SYSCONFDIR} (GNUInstallDirs' values) and the three overrides HAPTICD_INSTALL_{UNIT,UDEV,SYSUSERS}_DIR.
#
# The layout (docs/daemon.md "Install"):
#   prefix /usr (a distribution's layout, as GNUInstallDirs puts SYSCONFDIR at /etc for it):
#     /etc/hapticd/hapticd.toml, /lib/systemd/system/hapticd.service,
#     /lib/udev/rules.d/70-hapticd.rules, /usr/lib/sysusers.d/hapticd.conf (Debian 12's places),
#     /usr/share/lintian/overrides/hapticd
#   any other prefix P:
#     P/etc/hapticd/hapticd.toml, P/lib/systemd/system/hapticd.service,
#     P/lib/udev/rules.d/70-hapticd.rules, P/lib/sysusers.d/hapticd.conf
#   An absolute CMAKE_INSTALL_SYSCONFDIR is used as given; a non-empty override is taken relative
#   to the prefix, or as given when absolute.
# file(INSTALL) adds DESTDIR (cpack stages the package with it) and lists each file in the install
# manifest.

set(_prefix "${CMAKE_INSTALL_PREFIX}")
if(_prefix STREQUAL "/usr")
  set(_root "")  # the distribution's layout
else()
  set(_root "${_prefix}")
endif()

# hapticd_install_dir(VAR OVERRIDE DEFAULT): OVERRIDE when set (absolute, or relative to the
# prefix), else DEFAULT.
function(hapticd_install_dir var override default)
  if(override STREQUAL "")
    set(${var} "${default}" PARENT_SCOPE)
  elseif(IS_ABSOLUTE "${override}")
    set(${var} "${override}" PARENT_SCOPE)
  else()
    set(${var} "${_prefix}/${override}" PARENT_SCOPE)
  endif()
endfunction()

if(IS_ABSOLUTE "${HAPTICD_INSTALL_SYSCONFDIR}")
  set(_etc "${HAPTICD_INSTALL_SYSCONFDIR}")
elseif(_root STREQUAL "")
  set(_etc "/etc")
else()
  set(_etc "${_prefix}/${HAPTICD_INSTALL_SYSCONFDIR}")
endif()
hapticd_install_dir(_unit_dir "${HAPTICD_INSTALL_UNIT_DIR}" "${_root}/lib/systemd/system")
hapticd_install_dir(_udev_dir "${HAPTICD_INSTALL_UDEV_DIR}" "${_root}/lib/udev/rules.d")
hapticd_install_dir(_sysusers_dir "${HAPTICD_INSTALL_SYSUSERS_DIR}" "${_prefix}/lib/sysusers.d")

# The unit, from its template, pointing at this prefix's binary, config and docs.
set(HAPTICD_UNIT_BINDIR "${_prefix}/${HAPTICD_INSTALL_BINDIR}")
set(HAPTICD_UNIT_CONFDIR "${_etc}/hapticd")
set(HAPTICD_UNIT_DOCDIR "${_prefix}/${HAPTICD_INSTALL_DOCDIR}")
configure_file("${HAPTICD_SOURCE_DIR}/systemd/hapticd.service.in"
               "${HAPTICD_STAGE_DIR}/hapticd.service" @ONLY)
file(INSTALL DESTINATION "${_unit_dir}" TYPE FILE FILES "${HAPTICD_STAGE_DIR}/hapticd.service")

file(INSTALL DESTINATION "${_etc}/hapticd" TYPE FILE
     FILES "${HAPTICD_SOURCE_DIR}/config/hapticd.toml")
file(INSTALL DESTINATION "${_udev_dir}" TYPE FILE
     FILES "${HAPTICD_SOURCE_DIR}/systemd/70-hapticd.rules")
file(INSTALL DESTINATION "${_sysusers_dir}" TYPE FILE RENAME hapticd.conf
     FILES "${HAPTICD_SOURCE_DIR}/systemd/hapticd.sysusers")

# lintian's overrides (with their reasons): only in a distribution's layout (the package).
if(_root STREQUAL "")
  file(INSTALL DESTINATION "${_prefix}/share/lintian/overrides" TYPE FILE RENAME hapticd
       FILES "${HAPTICD_SOURCE_DIR}/packaging/debian/lintian-overrides")
endif()

# The changelog, compressed as Debian wants it (gzip -9, no name or time stamp: reproducible).
execute_process(COMMAND gzip -9nc "${HAPTICD_SOURCE_DIR}/packaging/debian/changelog"
                OUTPUT_FILE "${HAPTICD_STAGE_DIR}/changelog.gz" RESULT_VARIABLE _gzip_rc)
if(NOT _gzip_rc EQUAL 0)
  message(FATAL_ERROR "hapticd: gzip of packaging/debian/changelog failed (${_gzip_rc})")
endif()
file(INSTALL DESTINATION "${_prefix}/${HAPTICD_INSTALL_DOCDIR}" TYPE FILE
     FILES "${HAPTICD_STAGE_DIR}/changelog.gz")
