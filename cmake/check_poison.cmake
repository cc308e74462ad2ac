# Builds TARGET, which must fail to link because it allocates with operator
# new, and checks that the linker named the poisoned `new` itself (SYMBOL),
# not only the malloc it calls: the poison list must hold the target's own
# manglings (size_t is 32-bit on the Cortex-M4: _Znwj, not x86-64's _Znwm).
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGET}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "${TARGET} linked: the heap poison does not catch operator new")
endif()
if(NOT "${out}${err}" MATCHES "__wrap_${SYMBOL}")
  message(FATAL_ERROR "${TARGET} failed to link, but not on __wrap_${SYMBOL}: add this target's operator new "
                      "manglings to TONUS_HEAP_SYMBOLS\n${out}${err}")
endif()
message(STATUS "heap poison: ${TARGET} refused on __wrap_${SYMBOL}, as it should")
