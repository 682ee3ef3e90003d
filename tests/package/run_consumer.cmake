# Installs ecvpose into a temporary prefix, builds tests/package/consumer against it and runs it on a
# real frame. Called by ctest with -DSOURCE_DIR -DBUILD_DIR -DDATA_DIR.
set(work "${BUILD_DIR}/package_consumer")
# The consumer finds the package with the README's own line.
file(STRINGS "${SOURCE_DIR}/README.md" readme_line REGEX "^find_package\\(ecvpose ")
file(STRINGS "${SOURCE_DIR}/tests/package/consumer/CMakeLists.txt" consumer_line REGEX "^find_package\\(ecvpose ")
if(NOT readme_line OR NOT readme_line STREQUAL consumer_line)
  message(FATAL_ERROR "README.md's find_package line (${readme_line}) is not the consumer's (${consumer_line})")
endif()
file(REMOVE_RECURSE "${work}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "failed (${code}): ${ARGN}\n${out}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${work}/prefix")
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/tests/package/consumer" -B "${work}/build"
    -DCMAKE_PREFIX_PATH=${work}/prefix -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${work}/build")
run("${work}/build/frame_info" "${DATA_DIR}/ycbv_subset/Example-Scenes/0001/000001")
if(NOT output MATCHES "^1066.78 4")
  message(FATAL_ERROR "unexpected output of the consumer: ${output}")
endif()
message(STATUS "consumer printed: ${output}")

# The installed mesh importer program starts from the prefix (its libraries found there), and the installed CLI reads
# a mesh through it.
file(GLOB_RECURSE importer "${work}/prefix/*/ecvpose/ecvpose-mesh-import")
if(NOT importer)
  message(FATAL_ERROR "the install has no ecvpose/ecvpose-mesh-import beside the libraries")
endif()
execute_process(COMMAND ${importer} RESULT_VARIABLE code OUTPUT_QUIET ERROR_VARIABLE usage)
if(NOT code EQUAL 2 OR NOT usage MATCHES "^usage: ecvpose-mesh-import")
  message(FATAL_ERROR "the installed ${importer} did not start (${code}): ${usage}")
endif()
run("${work}/prefix/bin/ecvpose" info "${SOURCE_DIR}/models/meshes/003_cracker_box/003_cracker_box.obj")
if(NOT output MATCHES "triangles")
  message(FATAL_ERROR "unexpected output of the installed ecvpose info: ${output}")
endif()

# The installed Python package imports from the prefix's dist-packages (its libraries found there) and builds a
# model through the installed mesh importer.
if(EXISTS "${BUILD_DIR}/python/ecvpose/__init__.py")
  file(GLOB_RECURSE python_init "${work}/prefix/lib/*/__init__.py")
  list(FILTER python_init INCLUDE REGEX "dist-packages/ecvpose/__init__.py$")
  if(NOT python_init)
    message(FATAL_ERROR "the build has the Python package, the install has no dist-packages/ecvpose")
  endif()
  get_filename_component(package_dir "${python_init}" DIRECTORY)
  get_filename_component(dist_packages "${package_dir}" DIRECTORY)
  file(WRITE "${work}/check.py" [[
import sys
import ecvpose
assert ecvpose.__file__.startswith(sys.argv[1]), ecvpose.__file__
ecvpose.build_models(sys.argv[2], sys.argv[3], views=4)
print([model.name for model in ecvpose.ModelLibrary.open(sys.argv[2]).models])
]])
  run(${CMAKE_COMMAND} -E env "PYTHONPATH=${dist_packages}" /usr/bin/python3 "${work}/check.py" "${work}/prefix"
      "${work}/python.sqlite" "${SOURCE_DIR}/models/meshes/004_sugar_box")
  if(NOT output MATCHES "004_sugar_box")
    message(FATAL_ERROR "unexpected output of the installed Python package: ${output}")
  endif()
  message(STATUS "installed Python package built: ${output}")
endif()
