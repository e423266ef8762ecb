# SPDX-License-Identifier: Apache-2.0
# Runs at install time (see CellmapInstall.cmake): writes the systemd unit with the paths of this install,
# rewriting the ExecStart line only (the comments keep describing the by-hand install).
cmake_path(ABSOLUTE_PATH CELLMAPD_BINDIR BASE_DIRECTORY "${CMAKE_INSTALL_PREFIX}" OUTPUT_VARIABLE bindir)
cmake_path(ABSOLUTE_PATH CELLMAPD_SYSCONFDIR BASE_DIRECTORY "${CMAKE_INSTALL_PREFIX}" OUTPUT_VARIABLE etcdir)
file(READ "${CELLMAPD_UNIT_IN}" unit)
string(REGEX REPLACE "\nExecStart=/usr/local/bin/" "\nExecStart=${bindir}/" unit "${unit}")
string(REGEX REPLACE "(\nExecStart=[^\n]*)/etc/cellmap/" "\\1${etcdir}/cellmap/" unit "${unit}")
file(WRITE "${CELLMAPD_UNIT_OUT}" "${unit}")
