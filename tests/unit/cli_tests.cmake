# Unit tests for the scanplan CLI's terminal operator (target scanplan_cli_lib); include()d from
# tests/CMakeLists.txt. The region-decoding test draws its input with scanplan_core's own
# top-view renderer, so a change of the server's colours fails here and not in the field.
if(NOT TARGET GTest::gtest_main)
  find_package(GTest REQUIRED)
endif()
include(GoogleTest)

add_executable(scanplan_cli_tests
  ${CMAKE_CURRENT_LIST_DIR}/cli_operator_error_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cli_text_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cli_top_view_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/cli_websocket_client_test.cpp
)
target_link_libraries(scanplan_cli_tests PRIVATE scanplan_cli_lib scanplan_http scanplan_core
  opencv_imgcodecs GTest::gtest_main)
gtest_discover_tests(scanplan_cli_tests
  DISCOVERY_TIMEOUT 30
  PROPERTIES TIMEOUT 60 LABELS "unit;cli"
)
