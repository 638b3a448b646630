# What `cmake --install` installs and the Debian package `cpack -G DEB` builds from it
# (scripts/package.sh; docs/daemon.md "Install" and "The Debian package").
#
# Relative to the prefix (install() rules below):
#   bin/hapticd, bin/hapticctl                 the daemon (daemon/CMakeLists.txt) and the client
#   share/man/man8/hapticd.8.gz, man1/hapticctl.1.gz  their manual pages (help2man)
#   share/doc/hapticd/                         README.md, docs/*.md, copyright, changelog.gz, the
#                                              Python example
#   lib/python3/dist-packages/hapticd_client.py the Python client (importable as installed in /usr)
#   share/hapticd/web/                         the browser viewer (web/), when the tree has one
# Placed by the prefix at install time (cmake/InstallSystemFiles.cmake): the config, the systemd
# unit (written from systemd/hapticd.service.in), the udev rules, the sysusers entry.
# The package's expected contents: packaging/debian/contents.txt (scripts/package.sh --check and
# the package_install_layout test compare against it; update it with every change here).
include(GNUInstallDirs)

set(HAPTICD_INSTALL_UNIT_DIR "" CACHE STRING
    "hapticd.service's folder (relative to the prefix, or absolute); empty: by the prefix, see cmake/InstallSystemFiles.cmake")
set(HAPTICD_INSTALL_UDEV_DIR "" CACHE STRING
    "70-hapticd.rules' folder (relative to the prefix, or absolute); empty: by the prefix")
set(HAPTICD_INSTALL_SYSUSERS_DIR "" CACHE STRING
    "the hapticd group entry's folder (relative to the prefix, or absolute); empty: by the prefix")

# The unit as configured for this build's CMAKE_INSTALL_PREFIX (the daemon_unit_* tests check it;
# install writes it again for the prefix it installs to).
set(HAPTICD_UNIT_BINDIR "${CMAKE_INSTALL_FULL_BINDIR}")
set(HAPTICD_UNIT_CONFDIR "${CMAKE_INSTALL_FULL_SYSCONFDIR}/hapticd")
set(HAPTICD_UNIT_DOCDIR "${CMAKE_INSTALL_FULL_DOCDIR}")
set(HAPTICD_UNIT_FILE "${PROJECT_BINARY_DIR}/systemd/hapticd.service")
configure_file(${PROJECT_SOURCE_DIR}/systemd/hapticd.service.in ${HAPTICD_UNIT_FILE} @ONLY)

# --- binaries (hapticd's own rule is in daemon/CMakeLists.txt)
install(TARGETS hapticctl RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# --- manual pages: help2man from the built binaries' --help (so they list every option), with
# packaging/man/*.h2m's sections; hapticd(8), hapticctl(1), compressed as Debian wants them.
find_program(HAPTICD_HELP2MAN help2man)
if(HAPTICD_HELP2MAN AND TARGET hapticd)
  set(man_dir ${PROJECT_BINARY_DIR}/man)
  set(man_pages)
  foreach(page "hapticd;8;real-time 6-DOF haptic server"
               "hapticctl;1;command-line client of the hapticd haptic server")
    list(GET page 0 prog)
    list(GET page 1 section)
    list(GET page 2 summary)
    # run by name from its folder, so that the page shows "hapticctl", not the build path
    add_custom_command(
      OUTPUT ${man_dir}/${prog}.${section}.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${man_dir}
      COMMAND ${CMAKE_COMMAND} -E env "PATH=$<TARGET_FILE_DIR:${prog}>:/usr/bin:/bin"
              ${HAPTICD_HELP2MAN} --no-info --section=${section} --version-string=${PROJECT_VERSION}
              "--name=${summary}" --include=${PROJECT_SOURCE_DIR}/packaging/man/${prog}.h2m
              --output=${man_dir}/${prog}.${section} ${prog}
      COMMAND gzip -9nf ${man_dir}/${prog}.${section}
      DEPENDS ${prog} ${PROJECT_SOURCE_DIR}/packaging/man/${prog}.h2m
      COMMENT "help2man: ${prog}.${section}" VERBATIM)
    install(FILES ${man_dir}/${prog}.${section}.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man${section})
    list(APPEND man_pages ${man_dir}/${prog}.${section}.gz)
  endforeach()
  add_custom_target(hapticd_man_pages ALL DEPENDS ${man_pages})
else()
  message(WARNING "hapticd: help2man not found (Debian package help2man): no manual pages are "
                  "installed, and the Debian package lacks them (scripts/package.sh --check fails)")
endif()

# --- config, unit, udev rules, sysusers, changelog.gz: placed at install time
install(CODE "
  set(HAPTICD_SOURCE_DIR \"${PROJECT_SOURCE_DIR}\")
  set(HAPTICD_STAGE_DIR \"${PROJECT_BINARY_DIR}/packaging/installed\")
  set(HAPTICD_INSTALL_BINDIR \"${CMAKE_INSTALL_BINDIR}\")
  set(HAPTICD_INSTALL_DOCDIR \"${CMAKE_INSTALL_DOCDIR}\")
  set(HAPTICD_INSTALL_SYSCONFDIR \"${CMAKE_INSTALL_SYSCONFDIR}\")
  set(HAPTICD_INSTALL_UNIT_DIR \"${HAPTICD_INSTALL_UNIT_DIR}\")
  set(HAPTICD_INSTALL_UDEV_DIR \"${HAPTICD_INSTALL_UDEV_DIR}\")
  set(HAPTICD_INSTALL_SYSUSERS_DIR \"${HAPTICD_INSTALL_SYSUSERS_DIR}\")
")
install(SCRIPT ${PROJECT_SOURCE_DIR}/cmake/InstallSystemFiles.cmake)

# --- docs: the README, every docs/*.md, the copyright file Debian wants
file(GLOB HAPTICD_DOC_FILES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/docs/*.md)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${HAPTICD_DOC_FILES}
              ${PROJECT_SOURCE_DIR}/packaging/debian/copyright
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

# --- the Python client (issue 19 item 3): the module where Debian's python3 imports it from when
# the prefix is /usr (any other prefix: PYTHONPATH=P/lib/python3/dist-packages); its example with
# the docs.
install(FILES ${PROJECT_SOURCE_DIR}/client/python/hapticd_client.py
        DESTINATION lib/python3/dist-packages)
install(FILES ${PROJECT_SOURCE_DIR}/client/python/README.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/python RENAME README.md)
install(FILES ${PROJECT_SOURCE_DIR}/client/python/examples/record_states.py
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples)

# --- the browser viewer (issue 19 item 2): the one place to extend for it. Everything in web/
# (the page, its scripts, styles, images) goes to share/hapticd/web as it is laid out there, except
# npm's own files and the page's tests; of web/node_modules (npm install, the project's set-up), only
# the files the page imports, listed in HAPTICD_WEB_NPM_FILES, keep their path under
# share/hapticd/web/node_modules. With no web/ folder nothing is installed (packaging/debian/
# contents.txt says so). Each npm package shipped needs a paragraph with its copyright and licence
# in packaging/debian/copyright (three.js: MIT), not its LICENSE file (lintian: extra-license-file).
set(HAPTICD_WEB_DIR ${PROJECT_SOURCE_DIR}/web)
set(HAPTICD_WEB_NPM_FILES
    three/build/three.module.js
    three/examples/jsm/loaders/GLTFLoader.js
    three/examples/jsm/utils/BufferGeometryUtils.js)
if(EXISTS ${HAPTICD_WEB_DIR})
  install(DIRECTORY ${HAPTICD_WEB_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/hapticd/web
          PATTERN node_modules EXCLUDE PATTERN package.json EXCLUDE PATTERN package-lock.json EXCLUDE
          PATTERN tests EXCLUDE PATTERN .gitignore EXCLUDE)
  foreach(npm_file ${HAPTICD_WEB_NPM_FILES})
    get_filename_component(npm_dir ${npm_file} DIRECTORY)
    # a missing file fails the install: run the project's npm set-up first
    install(FILES ${HAPTICD_WEB_DIR}/node_modules/${npm_file}
            DESTINATION ${CMAKE_INSTALL_DATADIR}/hapticd/web/node_modules/${npm_dir})
  endforeach()
endif()

# --- the Debian package: cpack -G DEB in the release build (scripts/package.sh)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME hapticd)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})  # native: no Debian revision (packaging/debian/changelog)
set(CPACK_PACKAGE_CONTACT
    "hapticd maintainers <maintainers@users.noreply.h-seed-73ed00b7.example>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "real-time 6-DOF haptic server")
# the extended description (cpack puts the summary above it and indents it; no double quotes:
# CPackConfig.cmake does not keep them)
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "hapticd lets a person feel 6-DOF contact (force and torque) between rigid
polygonal objects through a force-feedback device, at 1 kHz and faster. It
implements the 6-DOF haptic display of polygonal models of Gregory et al.
(IEEE Visualization 2000).

This package holds the daemon (hapticd), its command-line client (hapticctl),
the Python 3 client module hapticd_client, the systemd unit, udev rules for
the supported devices and the documentation. The service is installed but
neither enabled nor started: choose the device in /etc/hapticd/hapticd.toml,
then run systemctl enable --now hapticd.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # hapticd_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Depends: computed by dpkg-shlibdeps from the binaries' shared libraries, never written here.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# python3 only for the optional Python client (hapticd itself needs none).
set(CPACK_DEBIAN_PACKAGE_SUGGESTS python3)
set(CPACK_STRIP_FILES ON)
set(CPACK_INSTALL_DEFAULT_DIRECTORY_PERMISSIONS
    OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
# Maintainer scripts (postinst, prerm, postrm) and the conffile list; strict permissions give the
# scripts 0755 and the rest 0644 as Debian policy asks.
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/packaging/debian/conffiles ${PROJECT_SOURCE_DIR}/packaging/debian/postinst
    ${PROJECT_SOURCE_DIR}/packaging/debian/prerm ${PROJECT_SOURCE_DIR}/packaging/debian/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
