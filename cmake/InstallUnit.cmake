# Runs at install time (see CellmapInstall.cmake): writes the systemd unit with the paths of this install.
cmake_path(ABSOLUTE_PATH CELLMAPD_BINDIR BASE_DIRECTORY "${CMAKE_INSTALL_PREFIX}" OUTPUT_VARIABLE bindir)
cmake_path(ABSOLUTE_PATH CELLMAPD_SYSCONFDIR BASE_DIRECTORY "${CMAKE_INSTALL_PREFIX}" OUTPUT_VARIABLE etcdir)
file(READ "${CELLMAPD_UNIT_IN}" unit)
string(REPLACE "/usr/local/bin/" "${bindir}/" unit "${unit}")
string(REPLACE "/etc/cellmap/" "${etcdir}/cellmap/" unit "${unit}")
file(WRITE "${CELLMAPD_UNIT_OUT}" "${unit}")
