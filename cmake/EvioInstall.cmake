# Installation and the Debian package.
#
# `evio` finds what it ships (presets, scenarios, campaigns, estimator
# configurations, plot scripts) in one data folder laid out like the
# repository, relative to its own binary (experiments/apps/data_root.h):
#   <prefix>/bin/evio  →  <prefix>/share/evio/{scenes/presets, experiments/scenarios, …}
# The build tree gets the same layout as links into the source tree, so
# `build/<preset>/bin/evio` and an installed `evio` find their data the same
# way and nothing of the source tree is compiled into the binary.
include(GNUInstallDirs)

set(EVIO_DATA_FOLDERS
  experiments/scenarios
  experiments/campaigns
  experiments/plots
  scenes/presets
  simulator/presets
  trajectories/presets
  estimator/config)
set(EVIO_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/evio)

# The data folder seen from the binary's folder ("../share/evio" by default).
file(RELATIVE_PATH EVIO_DATA_FROM_BIN
  ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR} ${CMAKE_INSTALL_PREFIX}/${EVIO_INSTALL_DATADIR})
set(EVIO_DATA_FROM_BIN ${EVIO_DATA_FROM_BIN} CACHE INTERNAL "data folder relative to the binary folder")

foreach(folder IN LISTS EVIO_DATA_FOLDERS)
  get_filename_component(parent ${folder} DIRECTORY)
  file(MAKE_DIRECTORY ${PROJECT_BINARY_DIR}/${EVIO_INSTALL_DATADIR}/${parent})
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/${folder} ${PROJECT_BINARY_DIR}/${EVIO_INSTALL_DATADIR}/${folder} SYMBOLIC)
  install(DIRECTORY ${folder}/ DESTINATION ${EVIO_INSTALL_DATADIR}/${folder}
          PATTERN "__pycache__" EXCLUDE)
endforeach()
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# Debian package: `cpack --config build/release/CPackConfig.cmake` (or
# `cmake --build build/release --target package`). Runtime dependencies come
# from dpkg-shlibdeps (the Debian libraries the binary links) plus Python
# and matplotlib for the plots.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME evio)
set(CPACK_PACKAGE_VENDOR "evio developers")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Event-camera visual-inertial odometry test bench: Mars-scene simulator, EKLT-VIO/KLT-VIO, campaigns")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "evio developers <evio@localhost>")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3, python3-matplotlib, python3-numpy")
set(CPACK_STRIP_FILES ON)
include(CPack)
