# Install, package and what the package carries besides the binary (docs/install.md).
# Included from the top CMakeLists.txt after the pitwall target.

# --version: the project's version, and `git describe` when built from a git checkout, written
# at every build (packaging/build_info.cmake rewrites the file only when it changes).
set(PITWALL_BUILD_INFO ${CMAKE_BINARY_DIR}/generated/build_info.cpp)
add_custom_target(build_info
  COMMAND ${CMAKE_COMMAND} -DSOURCE_DIR=${CMAKE_SOURCE_DIR} -DOUT=${PITWALL_BUILD_INFO}
    -DVERSION=${PROJECT_VERSION} "-DSDBUS_VERSION=${SDBUS_sdbus-c++_VERSION}"
    -P ${CMAKE_SOURCE_DIR}/packaging/build_info.cmake
  BYPRODUCTS ${PITWALL_BUILD_INFO}
  COMMENT "build info (version, git describe)")
target_sources(pitwall PRIVATE ${PITWALL_BUILD_INFO})
add_dependencies(pitwall build_info)

# Shell completion, from the binary's own command line (`pitwall completion bash|zsh`).
set(COMPLETIONS ${CMAKE_BINARY_DIR}/share/completions)
add_custom_command(OUTPUT ${COMPLETIONS}/pitwall ${COMPLETIONS}/_pitwall
  COMMAND ${CMAKE_COMMAND} -E make_directory ${COMPLETIONS}
  COMMAND $<TARGET_FILE:pitwall> completion bash > ${COMPLETIONS}/pitwall
  COMMAND $<TARGET_FILE:pitwall> completion zsh > ${COMPLETIONS}/_pitwall
  DEPENDS pitwall
  COMMENT "shell completion (bash, zsh)")
add_custom_target(completions ALL DEPENDS ${COMPLETIONS}/pitwall ${COMPLETIONS}/_pitwall)

# The view's code editor's completions, from the binary's own API definitions (`pitwall types
# --completions`, the same the LuaLS definitions are generated from): web/vendor/, beside the
# editor (docs/view.md)
file(GLOB TYPE_ANNOTATIONS CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/scripts/pitwall/types/*.lua)
set(EDITOR_COMPLETIONS ${PITWALL_VIEW_BUILD_DIR}/vendor/pitwall-completions.json)
add_custom_command(OUTPUT ${EDITOR_COMPLETIONS}
  COMMAND $<TARGET_FILE:pitwall> types --completions ${EDITOR_COMPLETIONS} > /dev/null
  DEPENDS pitwall ${CMAKE_SOURCE_DIR}/scripts/pitwall/types.lua ${TYPE_ANNOTATIONS}
  COMMENT "the code editor's completions (pitwall types --completions)")
add_custom_target(editor_completions ALL DEPENDS ${EDITOR_COMPLETIONS})

# The man page, by help2man from the binary's --help (packaging/manpage.sh).
find_program(HELP2MAN help2man)
set(MANPAGE ${CMAKE_BINARY_DIR}/share/man/man1/pitwall.1)
if(HELP2MAN)
  add_custom_command(OUTPUT ${MANPAGE}.gz
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/share/man/man1
    COMMAND bash ${CMAKE_SOURCE_DIR}/packaging/manpage.sh $<TARGET_FILE:pitwall> ${MANPAGE}
    COMMAND gzip -9nf ${MANPAGE}
    DEPENDS pitwall ${CMAKE_SOURCE_DIR}/packaging/manpage.sh
    COMMENT "the man page (help2man)")
  add_custom_target(manpage ALL DEPENDS ${MANPAGE}.gz)
else()
  message(WARNING "help2man not found: no man page (./dev installs help2man)")
endif()

# The installed tree (FHS): bin/pitwall finds share/pitwall beside it (engine/core/data_dir.hpp).
include(GNUInstallDirs)
install(TARGETS pitwall RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# the print module (track print, track verify), found beside the binary: bin/../lib/pitwall
install(TARGETS pitwall_print LIBRARY DESTINATION lib/pitwall)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/scripts/ DESTINATION ${CMAKE_INSTALL_DATADIR}/pitwall/scripts)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/examples/ DESTINATION ${CMAKE_INSTALL_DATADIR}/pitwall/examples)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/types/ DESTINATION ${CMAKE_INSTALL_DATADIR}/pitwall/types
  OPTIONAL)
install(DIRECTORY ${PITWALL_VIEW_BUILD_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/pitwall/web
  OPTIONAL)
install(FILES ${CMAKE_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs)
install(FILES ${COMPLETIONS}/pitwall
  DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
install(FILES ${COMPLETIONS}/_pitwall DESTINATION ${CMAKE_INSTALL_DATADIR}/zsh/vendor-completions)
install(FILES ${MANPAGE}.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 OPTIONAL)

# The Debian package: `./dev package` leaves build/pitwall_<version>_<arch>.deb. Its
# dependencies are the shared libraries the binary links, as dpkg-shlibdeps finds them.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME pitwall)
set(CPACK_PACKAGE_VENDOR "pitwall")
set(CPACK_PACKAGE_CONTACT "pitwall maintainers <pitwall@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "automation engine for robot race cars (Anki Overdrive, MindRoad, Alphabot), scripted in Lua")
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
  "pitwall drives Anki Overdrive cars over Bluetooth LE (BlueZ), MindRoad and Alphabot robots
 over TCP/UDP, and a built-in simulator, from Lua race scripts that hot-reload while the cars
 race; with a REPL, scenario tests in virtual time, a race view in the browser and an MQTT
 bridge that speaks the topic tree of the original controller.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "bluez")
set(CPACK_STRIP_FILES ON)
include(CPack)
