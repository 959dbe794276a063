# How ctest schedules this directory's tests (scripts/test.sh runs `ctest -j<cores>`): a label per
# kind (gtest, rostest, python: `ctest -L rostest` runs one kind), the long tests first (COST: about
# their seconds, so that two at a time finish together), and RUN_SERIAL for the tests that measure
# the wall-clock timing of a thread against a bound: nothing else runs beside them.
# Call after every test is added.
function(pca_schedule_tests)
  # regex of the test's name -> rough seconds it takes
  set(costs
    "platoon|paper_chain_20" 90
    "formation|vehicles" 45
    "invalid_parameters|formation_launch|hostile" 30
    "compare_neighbours|compare_qp|compare_barrier_filter" 25
    "plant_vehicles|faults|time_faults|paper_run|compare_with_reference" 15)
  set(serial "test_periodic_thread|test_shared_ticker|measurement_flood|follower_loop")
  get_property(tests DIRECTORY PROPERTY TESTS)
  foreach(test ${tests})
    string(REGEX MATCH "^_ctest_${PROJECT_NAME}_([a-z]+)_" kind "${test}")
    set_tests_properties(${test} PROPERTIES LABELS "${CMAKE_MATCH_1}")
    set(cost 1)
    list(LENGTH costs n)
    math(EXPR last "${n} - 2")
    foreach(i RANGE 0 ${last} 2)
      math(EXPR j "${i} + 1")
      list(GET costs ${i} pattern)
      if(test MATCHES "${pattern}")
        list(GET costs ${j} cost)
        break()
      endif()
    endforeach()
    set_tests_properties(${test} PROPERTIES COST ${cost})
    if(test MATCHES "${serial}")
      set_tests_properties(${test} PROPERTIES RUN_SERIAL TRUE)
    endif()
  endforeach()
endfunction()
