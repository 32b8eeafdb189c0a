# Builds the journal reader's libFuzzer target with clang (ASan + UBSan) and runs it for a short
# while on journals of real sweeps and maps. Called by ctest with -DSOURCE_DIR -DWORK_DIR -DRUNS.
# Exits with 77 (skipped) when clang or its fuzzer runtime is missing.
find_program(CLANGXX NAMES clang++ clang++-14)
if(NOT CLANGXX)
  message("clang++ not found: the fuzzer is skipped")
  cmake_language(EXIT 77)
endif()
file(REMOVE_RECURSE ${WORK_DIR}/corpus)
file(MAKE_DIRECTORY ${WORK_DIR}/corpus)
file(GLOB seeds ${SOURCE_DIR}/tests/study/journal_corpus/*.log)
file(COPY ${seeds} DESTINATION ${WORK_DIR}/corpus)
execute_process(
  COMMAND ${CLANGXX} -std=c++20 -O1 -g -fsanitize=fuzzer,address,undefined
          -fno-sanitize-recover=undefined -DFMT_HEADER_ONLY
          -I${SOURCE_DIR}/analysis/include -I${SOURCE_DIR}/lib/include -I/usr/include/eigen3
          ${SOURCE_DIR}/tests/study/journal_fuzzer.cpp
          ${SOURCE_DIR}/analysis/src/study/sweep_journal.cpp
          ${SOURCE_DIR}/analysis/src/study/indicators.cpp
          -o ${WORK_DIR}/journal_fuzzer
  RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  if(err MATCHES "libclang_rt.fuzzer|cannot find.*fuzzer")
    message("clang's fuzzer runtime is missing (libclang-rt-14-dev): the fuzzer is skipped")
    cmake_language(EXIT 77)
  endif()
  message(FATAL_ERROR "building the fuzzer failed:\n${err}")
endif()
execute_process(COMMAND ${WORK_DIR}/journal_fuzzer -runs=${RUNS} -seed=1 -timeout=10
                        -rss_limit_mb=2048 -max_len=16384 ${WORK_DIR}/corpus
                WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc ERROR_VARIABLE log)
string(REGEX MATCH "Done [0-9]+ runs[^\n]*" done "${log}")
message("${done}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the fuzzer found a failure (${rc}):\n${log}")
endif()
