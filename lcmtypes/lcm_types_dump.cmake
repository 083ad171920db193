# Writes `lcm-gen --debug` of LCM_DIR/*.lcm (lcm-gen's parse: each struct,
# then one "<type> <name> [dims]" line per field) to OUTPUT. A script because
# a custom command has no portable output redirection.
#   cmake -DLCM_GEN=... -DLCM_DIR=... -DOUTPUT=... -P lcm_types_dump.cmake
file(GLOB lcm_files ${LCM_DIR}/*.lcm)
execute_process(
  COMMAND ${LCM_GEN} --debug ${lcm_files}
  OUTPUT_FILE ${OUTPUT}
  RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  file(REMOVE ${OUTPUT})
  message(FATAL_ERROR "lcm-gen --debug failed (${result})")
endif()
