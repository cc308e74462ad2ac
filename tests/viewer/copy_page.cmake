# Copies the viewer's page (index.html, js/, css/) from SOURCE to DEST, fresh,
# without node_modules: a web root where three.js is not installed.
if(NOT SOURCE OR NOT DEST)
  message(FATAL_ERROR "usage: cmake -DSOURCE=host/viewer/web -DDEST=DIR -P copy_page.cmake")
endif()
file(REMOVE_RECURSE "${DEST}")
file(MAKE_DIRECTORY "${DEST}")
file(COPY "${SOURCE}/index.html" "${SOURCE}/js" "${SOURCE}/css" DESTINATION "${DEST}")
if(EXISTS "${DEST}/node_modules")
  message(FATAL_ERROR "${DEST} has node_modules")
endif()
message(STATUS "the page without three.js: ${DEST}")
