# The Debian package (scripts/package.sh): install rules for everything but the binary, and
# CPack's DEB generator. Included only with -DPLCEMU_PACKAGE=ON and CMAKE_INSTALL_PREFIX=/usr, so
# a plain `cmake --install` never writes into /etc or /lib (scripts/install.sh installs by hand
# into /usr/local and /etc/systemd/system and does not use these rules).
#
# CPack rather than dpkg-buildpackage: the package is built from the same CMake install rules
# as any other install, so there is no debian/ tree (rules, install lists, control) to keep in
# sync with the build, and the project's one build system stays the only one.

include(GNUInstallDirs)

set(PLCEMU_SYSTEMD_UNITDIR "/lib/systemd/system" CACHE PATH "Directory of the packaged units")
set(PLCEMU_MAINTAINER "plcemu maintainers <maintainers@localhost>"
    CACHE STRING "Maintainer field of the package and its changelog")

set(_pkg ${CMAKE_CURRENT_BINARY_DIR}/package)
file(MAKE_DIRECTORY ${_pkg})
set(_src ${CMAKE_CURRENT_SOURCE_DIR})

# The units: ExecStart follows the prefix, Documentation names the man pages and the packaged
# README (systemd/*.service name /usr/local, where scripts/install.sh puts the binary).
foreach(_unit plcemud.service plcemud@.service)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_src}/systemd/${_unit})
  file(READ ${_src}/systemd/${_unit} _text)
  string(REPLACE "/usr/local/bin/plcemud" "${CMAKE_INSTALL_FULL_BINDIR}/plcemud" _text "${_text}")
  string(REPLACE "Documentation=file:/usr/local/share/doc/plcemu/README.md"
                 "Documentation=man:plcemud(8) man:plcemud.yaml(5) file:${CMAKE_INSTALL_FULL_DOCDIR}/README.md"
                 _text "${_text}")
  string(REPLACE "(scripts/install.sh puts one there)" "(a conffile of the plcemu package)"
                 _text "${_text}")
  file(WRITE ${_pkg}/${_unit} "${_text}")
endforeach()

# /etc/plcemu/plcemud.yaml: config/default.yaml with a header for the installed file. It leaves
# persistence.file at its default, so under the unit the state file is
# /var/lib/plcemu/plcemud.state ($STATE_DIRECTORY from StateDirectory=plcemu).
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_src}/config/default.yaml)
file(READ ${_src}/config/default.yaml _text)
# The source tree's "Run it:" lines (the first and any indented continuation) mean nothing there.
string(REGEX REPLACE "# Run it:[^\n]*\n(#   +[^\n]*\n)?" "" _text "${_text}")
string(REPLACE "# See config/example.yaml for every key with its default.\n" "" _text "${_text}")
set(_header [=[
# /etc/plcemu/plcemud.yaml: the configuration of plcemud.service, installed by the plcemu
# package (a copy of /usr/share/doc/plcemu/examples/default.yaml; edits are kept on upgrade).
# It listens on 127.0.0.1:5020 only; a real PLC listens on 0.0.0.0:502 (modbus.tcp below).
# Check:  plcemud -c /etc/plcemu/plcemud.yaml --check-config
# Apply:  systemctl reload plcemud          Start: systemctl enable --now plcemud
# State:  persistence.file is left at its default, so the unit keeps the state file in
#         /var/lib/plcemu/plcemud.state (StateDirectory=). Run by hand, use the same file with
#         STATE_DIRECTORY=/var/lib/plcemu plcemud -c /etc/plcemu/plcemud.yaml
# Every key with its default: /usr/share/doc/plcemu/examples/example.yaml, man plcemud.yaml
#
]=])
string(REGEX REPLACE "^\n" "" _header "${_header}")
file(WRITE ${_pkg}/plcemud.yaml "${_header}${_text}")

# Man pages and the changelog, compressed as Debian wants them (gzip -9n: no name, no
# time stamp, so the package is reproducible).
string(TIMESTAMP PLCEMU_DEB_DATE "%a, %d %b %Y %H:%M:%S +0000" UTC)  # honours SOURCE_DATE_EPOCH
set(PLCEMU_DEB_VERSION ${PROJECT_VERSION})
# A native package (no Debian revision): lintian wants changelog.gz, not changelog.Debian.gz.
configure_file(${_src}/packaging/changelog.in ${_pkg}/changelog @ONLY)
set(_gz)
foreach(_f ${_src}/man/plcemud.8 ${_src}/man/plcemud.yaml.5 ${_pkg}/changelog)
  get_filename_component(_name ${_f} NAME)
  add_custom_command(OUTPUT ${_pkg}/${_name}.gz
                     COMMAND sh -c "gzip -9n -c '${_f}' > '${_pkg}/${_name}.gz'"
                     DEPENDS ${_f} VERBATIM)
  list(APPEND _gz ${_pkg}/${_name}.gz)
endforeach()
add_custom_target(plcemu_package_files ALL DEPENDS ${_gz})

install(FILES ${_pkg}/plcemud.service ${_pkg}/plcemud@.service
        DESTINATION ${PLCEMU_SYSTEMD_UNITDIR})
install(FILES ${_pkg}/plcemud.yaml DESTINATION ${CMAKE_INSTALL_FULL_SYSCONFDIR}/plcemu)
# Every configuration of config/ (the README and docs/ name them: vb.yaml, vb-pid.yaml,
# vb-mbus.yaml with the vb-mbus-slave.yaml it polls, fb-example.yaml, ...) and the programs
# they read (programs/*.il: oven-il.yaml runs programs/oven.il), not the state files a run
# leaves beside them.
install(DIRECTORY ${_src}/config/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples
        FILES_MATCHING PATTERN "*.yaml" PATTERN "*.il")
install(FILES ${_src}/README.md ${_src}/packaging/copyright ${_pkg}/changelog.gz
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The pages and the figures they show (docs/images/).
if(EXISTS ${_src}/docs)
  install(DIRECTORY ${_src}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs
          FILES_MATCHING PATTERN "*.md" PATTERN "*.png")
endif()
install(FILES ${_pkg}/plcemud.8.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man8)
install(FILES ${_pkg}/plcemud.yaml.5.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man5)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME plcemu)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${PLCEMU_MAINTAINER}")
set(CPACK_PACKAGING_INSTALL_PREFIX ${CMAKE_INSTALL_PREFIX})
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # plcemu_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${PLCEMU_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "FATEK FBs/FB and VIGOR VB PLC emulator (Modbus TCP/RTU slave)")
# The extended description; CPack puts the summary above it and indents it.
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "plcemud emulates a FATEK FBs, VIGOR VB or FATEK FB PLC as a Modbus TCP and
RTU slave: the family's register image and Modbus address map, a scan-cycle
engine running the manuals' temperature and PID instructions, and a
simulated thermal plant, so that a SCADA or HMI project can be run before
the plant exists.

The package installs the daemon, its man pages, a configuration in
/etc/plcemu and two systemd units (plcemud.service, plcemud@.service),
which it neither enables nor starts.")
# Depends from the libraries the binary links (libmodbus5, libyaml-cpp0.7, libspdlog1.10,
# libfmt9, libsystemd0, libstdc++6, libc6...), with the versions dpkg-shlibdeps finds.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${_src}/packaging/conffiles ${_src}/packaging/postinst ${_src}/packaging/prerm
    ${_src}/packaging/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_COMPRESSION_TYPE xz)
include(CPack)
