# Makes a bag for the rostests at test time (bags are build outputs, never committed):
#   cmake -DKITTI_TO_BAG=... -DOUTPUT=BAG -DSEQUENCE=DIR [-DELO_SIM=... -DSIM_ARGS=... [-DSIM_WRITES_BAG=ON]]
#         [-DPOSES_FRAME=...] -P make_test_bag.cmake
# With ELO_SIM, DIR is simulated first; without it, DIR must exist, else there is nothing to convert and
# the test that needs the bag skips (the shared real scans are absent on a fresh machine). SIM_WRITES_BAG:
# elo_sim writes the bag itself (--bag), with the per-point times that a KITTI .bin cannot hold.
if(ELO_SIM)
  file(REMOVE_RECURSE "${SEQUENCE}")
  separate_arguments(SIM_ARGS)
  set(bag_option)
  if(SIM_WRITES_BAG)
    set(bag_option --bag "${OUTPUT}")
  endif()
  execute_process(COMMAND "${ELO_SIM}" ${SIM_ARGS} --output "${SEQUENCE}" ${bag_option} RESULT_VARIABLE result)
  if(result)
    message(FATAL_ERROR "elo_sim failed (${result})")
  endif()
  if(SIM_WRITES_BAG)
    return()
  endif()
elseif(NOT IS_DIRECTORY "${SEQUENCE}")
  message(STATUS "${SEQUENCE} not found: no bag made, the test that replays it skips")
  return()
endif()
set(poses_option)
if(POSES_FRAME)
  set(poses_option --poses-frame ${POSES_FRAME})
endif()
execute_process(COMMAND "${KITTI_TO_BAG}" --input "${SEQUENCE}" --output "${OUTPUT}" ${poses_option}
                RESULT_VARIABLE result)
if(result)
  message(FATAL_ERROR "kitti_to_bag failed (${result})")
endif()
