# Speed tests: the timing statistics and the trade (host arithmetic only),
# the instruction counts of known shaders, the GPU pass timer on lavapipe
# (validation on), the speed results file, and `depthbench speed` as a user
# runs it.
depthbench_test(speed_stats_test speed_stats_test.cc LIBS depthbench_speed)
depthbench_test(instruction_mix_test instruction_mix_test.cc LIBS depthbench_speed)
depthbench_test(gpu_pass_timer_test gpu_pass_timer_test.cc LIBS depthbench_speed)
depthbench_test(speed_results_test speed_results_test.cc LIBS depthbench_speed)
depthbench_test(speed_cli_test speed_cli_test.cc LIBS depthbench_speed)
add_dependencies(speed_cli_test depthbench)
