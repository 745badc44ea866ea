# Builds the API documentation and fails on any Doxygen warning (test Augocc_Docs.*, label docs).
# Skipped (SKIPPED: on the output, SKIP_REGULAR_EXPRESSION) when Doxygen or bibtex, which
# @cite needs, is not installed; scripts/setup.sh installs both.
#   -DDOXYGEN=<doxygen or empty>  -DDOXYFILE=<the configured Doxyfile>
#   -DOUT_DIR=<output folder, replaced>  -DSOURCE_DIR=<repository root>
if(NOT DOXYGEN OR NOT EXISTS "${DOXYGEN}")
  message("SKIPPED: Doxygen not found (scripts/setup.sh installs it; then re-run cmake)")
  return()
endif()
find_program(BIBTEX bibtex)
find_program(PERL perl)
if(NOT BIBTEX OR NOT PERL)
  message("SKIPPED: bibtex or perl not found: Doxygen needs them for @cite "
          "(scripts/setup.sh installs texlive-base)")
  return()
endif()

file(REMOVE_RECURSE "${OUT_DIR}")
file(MAKE_DIRECTORY "${OUT_DIR}")
set(log "${OUT_DIR}/warnings.log")
# The project's Doxyfile with this test's own output folder and warning log.
file(WRITE "${OUT_DIR}/Doxyfile" "@INCLUDE = ${DOXYFILE}\n"
                                 "OUTPUT_DIRECTORY = ${OUT_DIR}\n"
                                 "WARN_LOGFILE = ${log}\n"
                                 "QUIET = YES\n")
execute_process(COMMAND "${DOXYGEN}" "${OUT_DIR}/Doxyfile" WORKING_DIRECTORY "${SOURCE_DIR}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(EXISTS "${log}")
  file(READ "${log}" warnings)
endif()
string(APPEND warnings "${err}")
string(STRIP "${warnings}" warnings)
if(NOT rc EQUAL 0 OR NOT warnings STREQUAL "")
  string(REPLACE "${SOURCE_DIR}/" "" warnings "${warnings}")
  string(REGEX MATCHALL "(warning|error):" hits "${warnings}")
  list(LENGTH hits n)
  message("${warnings}")
  message(FATAL_ERROR "Doxygen (exit ${rc}): ${n} warnings or errors, listed above")
endif()
message("docs: built in ${OUT_DIR}/html without a warning")
