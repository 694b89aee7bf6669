# Unit tests for server/http (target scanplan_http); include()d from tests/CMakeLists.txt.
if(NOT TARGET GTest::gtest_main)
  find_package(GTest REQUIRED)
endif()
include(GoogleTest)

add_executable(scanplan_http_tests
  ${CMAKE_CURRENT_LIST_DIR}/http_request_parser_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/http_response_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/http_router_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/http_static_files_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/http_server_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/websocket_frame_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/websocket_handshake_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/websocket_hub_test.cpp
  ${CMAKE_CURRENT_LIST_DIR}/websocket_utf8_test.cpp
)
target_link_libraries(scanplan_http_tests PRIVATE scanplan_http GTest::gtest_main)
gtest_discover_tests(scanplan_http_tests
  DISCOVERY_TIMEOUT 30
  PROPERTIES TIMEOUT 60 LABELS "unit;http"
)
