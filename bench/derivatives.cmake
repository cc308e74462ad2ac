# tonus-bench-derivatives: samples per second of the batch methods and of the
# fixed-lag push (included from bench/CMakeLists.txt).
add_executable(tonus-bench-derivatives ${CMAKE_CURRENT_LIST_DIR}/derivatives_bench.cpp)
target_link_libraries(tonus-bench-derivatives PRIVATE tonus::derivatives benchmark::benchmark tonus_warnings)
