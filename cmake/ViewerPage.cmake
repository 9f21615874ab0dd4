# The page of `scalespace view`: src/scalespace/viewer/web/*.js bundled with three.js by esbuild
# (npm packages installed by scripts/setup_web.sh) into <build>/viewer-page/app.js, beside
# index.html, where the program finds it (viewer/PageAssets.hpp); installed to
# share/scalespace/viewer-page. Without node_modules the build goes on without the page: the
# viewer then says how to get it, and the end-to-end test skips.
set(SCALESPACE_WEB_DIR ${CMAKE_CURRENT_SOURCE_DIR}/src/scalespace/viewer/web)
set(SCALESPACE_PAGE_DIR ${CMAKE_CURRENT_BINARY_DIR}/viewer-page)
set(SCALESPACE_ESBUILD ${SCALESPACE_WEB_DIR}/node_modules/.bin/esbuild)
find_program(SCALESPACE_NODE node)
if(EXISTS ${SCALESPACE_ESBUILD} AND EXISTS ${SCALESPACE_WEB_DIR}/node_modules/three/package.json
   AND SCALESPACE_NODE)
  file(GLOB page_sources CONFIGURE_DEPENDS ${SCALESPACE_WEB_DIR}/src/*.js)
  add_custom_command(
    OUTPUT ${SCALESPACE_PAGE_DIR}/app.js ${SCALESPACE_PAGE_DIR}/index.html
    COMMAND ${SCALESPACE_ESBUILD} ${SCALESPACE_WEB_DIR}/src/main.js --bundle --minify
            --format=esm --target=es2020 --log-level=warning
            --outfile=${SCALESPACE_PAGE_DIR}/app.js
    COMMAND ${CMAKE_COMMAND} -E copy ${SCALESPACE_WEB_DIR}/index.html
            ${SCALESPACE_PAGE_DIR}/index.html
    DEPENDS ${page_sources} ${SCALESPACE_WEB_DIR}/index.html ${SCALESPACE_WEB_DIR}/package-lock.json
    WORKING_DIRECTORY ${SCALESPACE_WEB_DIR}
    COMMENT "Bundling the viewer page (esbuild)")
  add_custom_target(scalespace_viewer_page ALL
                    DEPENDS ${SCALESPACE_PAGE_DIR}/app.js ${SCALESPACE_PAGE_DIR}/index.html)
  install(FILES ${SCALESPACE_PAGE_DIR}/app.js ${SCALESPACE_PAGE_DIR}/index.html
          DESTINATION ${CMAKE_INSTALL_DATADIR}/scalespace/viewer-page)
  set(SCALESPACE_VIEWER_PAGE ON)
else()
  message(STATUS "scalespace view: the page is not bundled (no node_modules in "
                 "src/scalespace/viewer/web: run scripts/setup_web.sh, then re-run cmake)")
  set(SCALESPACE_VIEWER_PAGE OFF)
endif()
