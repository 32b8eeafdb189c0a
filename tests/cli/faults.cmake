# Output that survives faults (included by tests/cli/CMakeLists.txt): a journal damaged in the
# middle, a full disk (a file size limit, and a 64 KiB tmpfs where a mount namespace can be made),
# a read-only output folder, and SIGINT/SIGTERM stopping a sweep; each ends, after --resume, with
# the same files byte for byte as an uninterrupted run. The scripts say what they check.
add_test(NAME cli_sweep_journal_damage
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/journal_damage.sh $<TARGET_FILE:pwl>
                 ${PWL_CLI_OUT}/journal_damage)
set_tests_properties(cli_sweep_journal_damage PROPERTIES PASS_REGULAR_EXPRESSION
                     "4 damaged lines named and recomputed; files identical.*foreign and conflicting records refused")
add_test(NAME cli_sweep_full_disk_ulimit
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/full_disk.sh $<TARGET_FILE:pwl>
                 ${PWL_CLI_OUT}/full_disk_ulimit ulimit)
set_tests_properties(cli_sweep_full_disk_ulimit PROPERTIES PASS_REGULAR_EXPRESSION
                     "resumed, identical.*files written by --resume, identical")
add_test(NAME cli_sweep_full_disk_tmpfs
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/full_disk.sh $<TARGET_FILE:pwl>
                 ${PWL_CLI_OUT}/full_disk_tmpfs tmpfs)
set_tests_properties(cli_sweep_full_disk_tmpfs PROPERTIES SKIP_RETURN_CODE 77
                     PASS_REGULAR_EXPRESSION "No space left on device.*resumed, identical")
add_test(NAME cli_sweep_read_only_folder
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/read_only_folder.sh $<TARGET_FILE:pwl>
                 ${PWL_CLI_OUT}/read_only_folder)
set_tests_properties(cli_sweep_read_only_folder PROPERTIES SKIP_RETURN_CODE 77
                     PASS_REGULAR_EXPRESSION "read-only folders refused, nothing lost, resumed identical")
# Points of 40000 forcing periods, 4000 under the sanitizers (the same second or so a point).
if(PWL_SANITIZE)
  set(PWL_STOP_SIGNALS_TRANSIENT 4000)
else()
  set(PWL_STOP_SIGNALS_TRANSIENT 40000)
endif()
add_test(NAME cli_sweep_stop_signals
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/stop_signals.sh $<TARGET_FILE:pwl>
                 ${PWL_CLI_OUT}/stop_signals ${PWL_STOP_SIGNALS_TRANSIENT})
set_tests_properties(cli_sweep_stop_signals PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 600
                     PASS_REGULAR_EXPRESSION "stopped by SIGINT and SIGTERM, resumed, identical")
# The same stop in the middle of pwl continue --curves (release only: the curves take a while
# under the sanitizers before there are rows to stop between).
add_test(NAME cli_curves_stop_signals
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/stop_curves.sh $<TARGET_FILE:pwl>
                 ${PWL_CLI_OUT}/stop_curves)
set_tests_properties(cli_curves_stop_signals PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300
                     PASS_REGULAR_EXPRESSION "stopped by SIGINT and SIGTERM, every row whole"
                     LABELS release-only)
