# Vulkan backend tests (owned by the Vulkan backend work): the std430 layout
# contract, the glslang shader compiler, and the backend on lavapipe, in its
# compute and raster forms.
depthbench_test(layout_test layout_test.cc LIBS depthbench_backends)
depthbench_test(shader_compiler_test shader_compiler_test.cc LIBS depthbench_backends)
depthbench_test(vulkan_backend_test vulkan_backend_test.cc LIBS depthbench_backends)
depthbench_test(variant_file_test variant_file_test.cc LIBS depthbench_sweep depthbench_backends)
depthbench_test(arithmetic_probe_test arithmetic_probe_test.cc LIBS depthbench_backends SPIRV-Tools-static)
depthbench_test(raster_pass_test raster_pass_test.cc LIBS depthbench_backends)
depthbench_test(raster_pipeline_test raster_pipeline_test.cc LIBS depthbench_sweep depthbench_backends ONE_PROCESS)
depthbench_test(device_judge_test device_judge_test.cc LIBS depthbench_sweep depthbench_backends)
