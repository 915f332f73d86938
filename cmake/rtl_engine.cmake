# The rtl engine (src/filter/rtl_engine.cc, docs/HARDWARE.md §16): the hw engine with its
# weighing pipeline in Verilated SystemVerilog (src/hw/rtl/weigh_accel.sv, M = 5), driven by the
# host driver src/hw/host/weigh_driver.cc over src/hw/host/verilator_transport.cc (the default)
# or, on a board, src/hw/host/uio_transport.cc (POSEFILTER_RTL_DEVICE, src/filter/rtl_engine.h).
# POSEFILTER_RTL_ENGINE (CMakeLists.txt) is ON when Verilator is installed (Debian `verilator`;
# scripts/setup.sh) and OFF in the sanitizer presets asan, tsan and debug (Verilated code is not
# built under ASan/TSan). OFF: the engine reports that this build has no RTL
# (src/hw/host/verilator_transport_none.cc).
#
# Included by src/hw/CMakeLists.txt: the host side goes into the hw layer, posefilter_hw. The
# Verilated top is one object library, posefilter_rtl_model, built once; its objects go into
# posefilter_hw, so the CLI, the Python module and the tests link them from there (an object
# library keeps the Verilator include paths out of the library's exported interface).
# Cheap to build: the generated model at -O1 (its slow-path code at -O0), assertions on.
target_sources(posefilter_hw PRIVATE ${PROJECT_SOURCE_DIR}/src/hw/host/weigh_driver.cc)
# The board's transport (docs/HARDWARE.md §17: UIO registers and interrupt, a u-dma-buf; plain
# POSIX, no Verilator), selected at run time with POSEFILTER_RTL_DEVICE=uio[:NAME[:UDMABUF]]:
# in every Linux build, with or without the Verilated model.
if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
  target_sources(posefilter_hw PRIVATE ${PROJECT_SOURCE_DIR}/src/hw/host/uio_transport.cc)
endif()
set_source_files_properties(${PROJECT_SOURCE_DIR}/src/hw/host/weigh_driver.cc
  PROPERTIES COMPILE_OPTIONS "-Wno-unknown-pragmas;-Wno-unused-label")
if(POSEFILTER_RTL_ENGINE)
  if(NOT verilator_FOUND)
    message(FATAL_ERROR "POSEFILTER_RTL_ENGINE=ON needs Verilator (Debian package verilator): run scripts/setup.sh")
  endif()
  set(rtl_dir ${PROJECT_SOURCE_DIR}/src/hw/rtl)
  add_library(posefilter_rtl_model OBJECT ${PROJECT_SOURCE_DIR}/src/hw/host/verilator_transport.cc)
  target_include_directories(posefilter_rtl_model PRIVATE ${PROJECT_SOURCE_DIR}/src ${PROJECT_SOURCE_DIR}/include)
  target_compile_features(posefilter_rtl_model PRIVATE cxx_std_20)
  set_target_properties(posefilter_rtl_model PROPERTIES POSITION_INDEPENDENT_CODE ON)
  verilate(posefilter_rtl_model
    SOURCES ${rtl_dir}/weigh_regs_pkg.sv ${rtl_dir}/rc_pkg.sv ${rtl_dir}/rc_div.sv ${rtl_dir}/rc_delay.sv
            ${rtl_dir}/rc_fifo.sv ${rtl_dir}/rc_compare.sv ${rtl_dir}/rc_vertex_stage.sv ${rtl_dir}/raster_core.sv
            ${rtl_dir}/ft_distributor.sv ${rtl_dir}/vertex_multiplier.sv ${rtl_dir}/depth_distributor.sv
            ${rtl_dir}/weight_merger.sv ${rtl_dir}/weigh_pipeline.sv ${rtl_dir}/axi_burst_reader.sv
            ${rtl_dir}/axi_record_writer.sv ${rtl_dir}/weigh_accel.sv
    TOP_MODULE weigh_accel
    PREFIX Vweigh_accel
    VERILATOR_ARGS -Wno-fatal -Wno-WIDTH -Wno-UNUSEDSIGNAL -Wno-SYMRSVDWORD -O3 --x-assign fast --x-initial fast
                   --assert -GM=5
    OPT_FAST -O1
    OPT_SLOW -O0
    OPT_GLOBAL -O1)
  target_sources(posefilter_hw PRIVATE $<TARGET_OBJECTS:posefilter_rtl_model>)
  add_dependencies(posefilter_hw posefilter_rtl_model)
else()
  target_sources(posefilter_hw PRIVATE ${PROJECT_SOURCE_DIR}/src/hw/host/verilator_transport_none.cc)
endif()
