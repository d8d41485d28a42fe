# mc_add_module(NAME [DEPS mc_a mc_b ...] [LIBS ...])
# One static library per folder src/microcobot/NAME (every .cc in it), target mc_NAME.
# A folder without sources yet is skipped, and so are dependencies that do not exist yet.
function(mc_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;LIBS" ${ARGN})
  file(GLOB _sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${name}/*.cc)
  if(NOT _sources)
    return()
  endif()
  set(_deps)
  foreach(_d IN LISTS ARG_DEPS)
    if(TARGET ${_d})
      list(APPEND _deps ${_d})
    endif()
  endforeach()
  if(NOT name STREQUAL "core")
    list(APPEND _deps mc_core)
  endif()
  add_library(mc_${name} STATIC ${_sources})
  target_include_directories(mc_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(mc_${name} PUBLIC ${_deps} ${ARG_LIBS} PRIVATE mc_warnings)
  mc_unity_build(mc_${name})
  set_property(GLOBAL APPEND PROPERTY MC_MODULES mc_${name})
endfunction()

# Unity build of a library or of the command line (MC_UNITY_LIBS): as for the tests, a file's
# helpers in its anonymous namespace must have names of their own within its module.
function(mc_unity_build target)
  if(MC_UNITY_LIBS)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${MC_UNITY_LIBS_BATCH_SIZE})
  endif()
endfunction()

# Embeds the charting library (uPlot, pinned by package-lock.json) into the binary so that
# reports are single self-contained HTML files that open offline.
function(mc_embed_report_assets target)
  set(_js ${PROJECT_SOURCE_DIR}/node_modules/uplot/dist/uPlot.iife.min.js)
  set(_css ${PROJECT_SOURCE_DIR}/node_modules/uplot/dist/uPlot.min.css)
  if(NOT EXISTS ${_js} OR NOT EXISTS ${_css})
    message(FATAL_ERROR "uPlot not found in node_modules: run scripts/install-deps.sh (or make run)")
  endif()
  set(_out ${PROJECT_BINARY_DIR}/generated/report_assets.cc)
  set(_page_js ${PROJECT_SOURCE_DIR}/web/report.js)
  set(_page_css ${PROJECT_SOURCE_DIR}/web/report.css)
  add_custom_command(OUTPUT ${_out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${_out} -DJS=${_js} -DCSS=${_css} -DPAGE_JS=${_page_js}
            -DPAGE_CSS=${_page_css} -P ${PROJECT_SOURCE_DIR}/cmake/embed_assets.cmake
    DEPENDS ${_js} ${_css} ${_page_js} ${_page_css} ${PROJECT_SOURCE_DIR}/cmake/embed_assets.cmake
    COMMENT "Embedding uPlot into the report writer")
  target_sources(${target} PRIVATE ${_out})
endfunction()

# The properties of a heavy test: one that loads a core or more on its own (a `serve` and a
# browser, two real-time loops in two processes, a twin and its driver). It runs alone: beside
# another heavy test the two starve each other's loops and frames, and letting the heavy tests take
# turns beside the light ones (one resource lock) did not shorten `make test` on two cores (1429 s
# against 1382-1422 s: both kinds slowed, the heavy ones already keep the second core busy).
set(MC_HEAVY_TEST_PROPERTIES RUN_SERIAL TRUE)

# A test's own code (its assertions, gtest's and gmock's templates) compiled at -O1 in the release
# tree: a quarter less compile time than -O3 (motion_tests' two unity batches, 47.5 s of CPU
# against 34.8 s), while what it exercises runs from the libraries, optimised as they ship.
function(mc_test_code_optimization target)
  if(CMAKE_BUILD_TYPE STREQUAL "Release")
    target_compile_options(${target} PRIVATE -O1)
  endif()
endfunction()

# mc_add_module_tests(NAME [LIBS ...] [LABELS ...] [SERIAL gtest-filter] [NEEDS_CLI gtest-filter])
# Every tests/NAME/*_test.cc goes into the executable NAME_tests, registered with CTest. Tests
# matching SERIAL are heavy (MC_HEAVY_TEST_PROPERTIES); tests matching NEEDS_CLI run the command
# line as a process and are registered only in a tree that builds it (MC_BUILD_CLI).
function(mc_add_module_tests name)
  cmake_parse_arguments(ARG "" "SERIAL;NEEDS_CLI" "LIBS;LABELS" ${ARGN})
  if(NOT MC_TEST_MODULES STREQUAL "all" AND NOT name IN_LIST MC_TEST_MODULES)
    return()
  endif()
  file(GLOB _sources CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/${name}/*_test.cc)
  if(NOT _sources OR (NOT TARGET mc_${name} AND NOT name MATCHES "^(cli|acceptance)$"))
    return()
  endif()
  add_executable(${name}_tests ${_sources})
  # A module outside the library `microcobot` (the studies) is linked by its own tests.
  if(TARGET mc_${name})
    list(APPEND ARG_LIBS mc_${name})
  endif()
  target_link_libraries(${name}_tests PRIVATE microcobot mc_test_support ${ARG_LIBS}
    GTest::gtest GTest::gmock GTest::gtest_main mc_warnings)
  target_compile_definitions(${name}_tests PRIVATE
    MC_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data"
    MC_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    MC_CLI_PATH="${MC_CLI_FILE}")
  if(TARGET microcobot_cli)
    add_dependencies(${name}_tests microcobot_cli)
  endif()
  mc_test_code_optimization(${name}_tests)
  # Unity build (MC_UNITY_TESTS, CMakeLists.txt): the test files of a module are compiled a few at a
  # time in one translation unit, so gtest, gmock, nlohmann::json and Eigen are parsed once per
  # batch rather than once per file. Each file's helpers must therefore have names of their own
  # (two files' anonymous namespaces are one namespace in a batch).
  if(MC_UNITY_TESTS)
    set_target_properties(${name}_tests PROPERTIES UNITY_BUILD ON
      UNITY_BUILD_BATCH_SIZE ${MC_UNITY_TESTS_BATCH_SIZE})
  endif()
  set(_skip "")
  if(ARG_NEEDS_CLI AND NOT TARGET microcobot_cli)
    set(_skip "${ARG_NEEDS_CLI}")
  endif()
  if(ARG_SERIAL)
    set(_light "-${ARG_SERIAL}")
    set(_heavy "${ARG_SERIAL}")
    if(_skip)
      string(APPEND _light ":${_skip}")
      string(APPEND _heavy "-${_skip}")
    endif()
    gtest_discover_tests(${name}_tests DISCOVERY_TIMEOUT 60 TEST_FILTER "${_light}"
      PROPERTIES LABELS "${name};${ARG_LABELS}")
    gtest_discover_tests(${name}_tests DISCOVERY_TIMEOUT 60 TEST_FILTER "${_heavy}"
      PROPERTIES LABELS "${name};${ARG_LABELS}" ${MC_HEAVY_TEST_PROPERTIES})
  elseif(_skip)
    gtest_discover_tests(${name}_tests DISCOVERY_TIMEOUT 60 TEST_FILTER "-${_skip}"
      PROPERTIES LABELS "${name};${ARG_LABELS}")
  else()
    gtest_discover_tests(${name}_tests DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS "${name};${ARG_LABELS}")
  endif()
endfunction()

# Embeds the live console's page, scripts and styles (web/console*.{html,js,css}) into `target`,
# so that `microcobot serve` serves a console that works offline (uPlot comes from the report's
# assets). The page names each file it inlines (console_page.cc).
function(mc_embed_console_assets target)
  set(_out ${PROJECT_BINARY_DIR}/generated/console_assets.cc)
  set(_files)
  foreach(_f console.html console.css console_link.js console_plots.js console_microscope.js console_camera.js
             console_controls.js console_positions.js console_positioner.js console_status.js console_task.js)
    list(APPEND _files ${PROJECT_SOURCE_DIR}/web/${_f})
  endforeach()
  string(REPLACE ";" "\\;" _list "${_files}")
  add_custom_command(OUTPUT ${_out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${_out} -DNAMESPACE=mc::live::assets "-DFILES=${_list}"
            -P ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${_files} ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding the live console")
  target_sources(${target} PRIVATE ${_out})
endfunction()
