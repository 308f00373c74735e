# cmake -DSRC=<page files> -DNODE_MODULES=<tools/view-web/node_modules> -DDEST=<dir> -P CopyViewWeb.cmake
# Copies the view's page and, when npm installed them, the libraries it imports into DEST/vendor.
# A missing library leaves DEST/vendor without it; the page then says to run tools/setup.sh.
file(MAKE_DIRECTORY ${DEST}/vendor)
file(GLOB page_files ${SRC}/*)
file(COPY ${page_files} DESTINATION ${DEST})
set(vendor_files
  three/build/three.module.min.js
  three/examples/jsm/controls/OrbitControls.js
  uplot/dist/uPlot.iife.min.js
  uplot/dist/uPlot.min.css
  three/LICENSE
  uplot/LICENSE)
set(missing "")
foreach(f ${vendor_files})
  if(EXISTS ${NODE_MODULES}/${f})
    string(REPLACE "/" "_" flat ${f})
    string(REGEX REPLACE "^(three|uplot)_(build|examples_jsm_controls|dist)_" "" flat ${flat})
    configure_file(${NODE_MODULES}/${f} ${DEST}/vendor/${flat} COPYONLY)
  else()
    list(APPEND missing ${f})
  endif()
endforeach()
if(missing)
  message(STATUS "view: not in ${NODE_MODULES}: ${missing}; run tools/setup.sh (npm ci in tools/view-web) and rebuild")
endif()
