# ctest driver of the glTF export test (cmake -P). Makes a small synthetic 3D
# photo, encodes it as a package, exports it with `casual3d export` as a plain
# and a Draco GLB, and checks both with tests/node/gltf_test.mjs (Khronos glTF
# validator, three.js GLTFLoader + Draco). Also exports the master file and the
# single-file package to cover every kind of input.
#
# Variables: CASUAL3D (the program), NODE (node), SOURCE_DIR (source tree),
# WORK_DIR (scratch folder, emptied first).

foreach(var CASUAL3D NODE SOURCE_DIR WORK_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_gltf_test.cmake: -D${var}=... is required")
  endif()
endforeach()
set(node_modules "${SOURCE_DIR}/wasm-viewer/node_modules")
if(NOT EXISTS "${node_modules}/three/package.json")
  message(FATAL_ERROR "${node_modules}: npm packages missing; run scripts/setup.sh "
                      "(or 'npm ci' in wasm-viewer/)")
endif()

file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(run)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY "${WORK_DIR}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "failed (${rc}): ${cmd}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

# A 256x128 ground-truth panorama (the synthetic room), as master and package.
run("${CASUAL3D}" synth --width 64 --photos 2 --panorama-width 256 -o capture)
run("${CASUAL3D}" encode capture/ground_truth/master.exr -o package --single-file photo.c3d
    --no-viewer)

# Plain and Draco GLB of the package, simplified to a budget.
run("${CASUAL3D}" export package --glb plain.glb --max-triangles 30000 --max-error 0.05)
message(STATUS "${run_output}")
if(NOT run_output MATCHES "wrote plain.glb: [0-9]+ vertices, ([0-9]+) triangles")
  message(FATAL_ERROR "unexpected output of casual3d export: ${run_output}")
endif()
set(triangles "${CMAKE_MATCH_1}")
if(triangles GREATER 30000 OR triangles LESS 1000)
  message(FATAL_ERROR "plain.glb has ${triangles} triangles, expected 1000..30000")
endif()
run("${CASUAL3D}" export package --glb draco.glb --draco --max-triangles 30000 --max-error 0.05)
message(STATUS "${run_output}")

run("${NODE}" "${SOURCE_DIR}/tests/node/gltf_test.mjs" --node-modules "${node_modules}"
    --plain plain.glb --draco draco.glb --triangles ${triangles})
message(STATUS "${run_output}")

# The other inputs: the master file (full mesh, PNG texture), and the .c3d
# file, which holds the same package as the folder and so the same mesh.
run("${CASUAL3D}" export capture/ground_truth/master.exr --glb master.glb --no-simplify
    --texture png)
message(STATUS "${run_output}")
run("${CASUAL3D}" export capture/ground_truth/master.exr --glb master_draco.glb --no-simplify
    --texture png --draco)
message(STATUS "${run_output}")
run("${NODE}" "${SOURCE_DIR}/tests/node/gltf_test.mjs" --node-modules "${node_modules}"
    --plain master.glb --draco master_draco.glb)
message(STATUS "${run_output}")
run("${CASUAL3D}" export photo.c3d --glb single.glb --draco --max-triangles 30000
    --max-error 0.05)
message(STATUS "${run_output}")
run("${NODE}" "${SOURCE_DIR}/tests/node/gltf_test.mjs" --node-modules "${node_modules}"
    --plain plain.glb --draco single.glb --triangles ${triangles})
message(STATUS "${run_output}")

# A bad input gives one clear line and no output file.
execute_process(COMMAND "${CASUAL3D}" export capture/capture.json --glb bad.glb
                WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "^casual3d: error: capture/capture.json: " OR
   EXISTS "${WORK_DIR}/bad.glb")
  message(FATAL_ERROR "a JSON file as input: expected a one-line error, got rc ${rc}: ${err}")
endif()
