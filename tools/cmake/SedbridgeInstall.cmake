# `cmake --install build --prefix P` gives a tree that runs without the source:
#   P/bin/sedbridge, sedbridge-display-driver, leader_press_compare
#   P/share/sedbridge/{config,tools}          shipped configs, models, scripts (plots, lcm-spy)
#   P/share/sedbridge/python/{sedbridge,sedbridge_lcm.py}   Python LCM types + runtime
#   P/share/sedbridge/java/sedbridge_lcmtypes.jar           lcm-spy types (when a JDK built it)
#   P/include/sedbridge/lcmt_*.hpp            C++ LCM types
#   P/share/doc/sedbridge/{LICENSE,README.md}
# The installed binary finds P/share/sedbridge from its own location (src/common/resource_path.h).
# `cpack -G DEB` (in build/) packages the same tree as a .deb.

set(SEDBRIDGE_INSTALL_DATA ${CMAKE_INSTALL_DATADIR}/sedbridge)

# The bridge and the driver that runs beside the display (docs/two-host.md).
install(TARGETS sedbridge sedbridge-display-driver RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET leader_press_compare)
  install(TARGETS leader_press_compare RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config DESTINATION ${SEDBRIDGE_INSTALL_DATA})
# Scripts only: the model generator's and fidelity study's C++ sources and the CMake files stay behind.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/tools DESTINATION ${SEDBRIDGE_INSTALL_DATA}
        USE_SOURCE_PERMISSIONS
        PATTERN fingertip_generator EXCLUDE
        PATTERN bridge_fidelity_study EXCLUDE
        PATTERN leader_press_compare.cpp EXCLUDE
        PATTERN CMakeLists.txt EXCLUDE
        PATTERN view-web EXCLUDE
        PATTERN __pycache__ EXCLUDE)
# The view's page with the libraries the build copied beside it (`sedbridge view` finds it in
# share/sedbridge/view_web when it runs from an installed tree).
if(TARGET sedbridge_view)
  install(DIRECTORY ${SEDBRIDGE_VIEW_WEB_DIR}/ DESTINATION ${SEDBRIDGE_INSTALL_DATA}/view_web)
endif()
install(DIRECTORY ${SEDBRIDGE_LCM_PYTHON_DIR}/ DESTINATION ${SEDBRIDGE_INSTALL_DATA}/python
        PATTERN __pycache__ EXCLUDE)
install(DIRECTORY ${PROJECT_BINARY_DIR}/lcmtypes/cpp/sedbridge DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET sedbridge_lcmtypes_jar)
  install(FILES ${PROJECT_BINARY_DIR}/lcmtypes/sedbridge_lcmtypes.jar DESTINATION ${SEDBRIDGE_INSTALL_DATA}/java)
endif()
if(TARGET make_fingertip_models)
  install(TARGETS make_fingertip_models RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} OPTIONAL)
endif()
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# ---- Debian package (cpack -G DEB) ----
set(CPACK_PACKAGE_NAME sedbridge)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "tactile sensor -> fingertip FE model -> Merkel-layer SED -> haptic display over LCM")
set(CPACK_PACKAGE_CONTACT "sedbridge maintainers")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_GENERATOR DEB)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
# Runtime libraries from the Debian packages tools/setup.sh installs.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3-matplotlib, python3-numpy, liblcm-bin, liblcm-java, libjchart2d-java")
include(CPack)
