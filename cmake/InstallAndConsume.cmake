# ctest InstallAndConsume: cmake -P script, run by the top-level CMakeLists.txt.
#   1. cmake --install <build> --prefix <build>/test-install (a fresh prefix)
#   2. check the installed layout (package, module library, headers, plugin)
#   3. configure Examples/Consumer against that prefix only, build it, run it
#   4. with ParaView: load the installed plugin in pvpython (its RPATH must find the
#      installed module library)
#   5. with the Python package: Testing/Python/test_package.py against the installed
#      package, in python3 and in pvpython
# Any failure stops the script with FATAL_ERROR, which fails the test.
cmake_minimum_required(VERSION 3.16)

foreach(var IN ITEMS VAO_BUILD_DIR VAO_INSTALL_PREFIX VAO_CONSUMER_SOURCE_DIR
    VAO_CONSUMER_BINARY_DIR VAO_GENERATOR VAO_LIBDIR VAO_INCLUDEDIR)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "InstallAndConsume: ${var} is not set")
  endif()
endforeach()

function(vao_run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "InstallAndConsume: ${what} failed (${rc}): ${ARGN}")
  endif()
endfunction()

function(vao_expect path)
  if(NOT EXISTS "${VAO_INSTALL_PREFIX}/${path}")
    message(FATAL_ERROR "InstallAndConsume: not installed: ${VAO_INSTALL_PREFIX}/${path}")
  endif()
  message(STATUS "installed: ${path}")
endfunction()

set(config_args)
if(VAO_CONFIG)
  set(config_args --config "${VAO_CONFIG}")
endif()

# 1. Install into a fresh prefix.
file(REMOVE_RECURSE "${VAO_INSTALL_PREFIX}" "${VAO_CONSUMER_BINARY_DIR}")
vao_run("install" "${CMAKE_COMMAND}" --install "${VAO_BUILD_DIR}"
  --prefix "${VAO_INSTALL_PREFIX}" ${config_args})

# 2. The layout.
vao_expect("${VAO_LIBDIR}/cmake/VolumetricAO/VolumetricAOConfig.cmake")
vao_expect("${VAO_LIBDIR}/cmake/VolumetricAO/VolumetricAOConfigVersion.cmake")
vao_expect("${VAO_LIBDIR}/cmake/VolumetricAO/VolumetricAO-targets.cmake")
vao_expect("${VAO_LIBDIR}/cmake/VolumetricAO/VolumetricAO-vtk-module-properties.cmake")
vao_expect("${VAO_LIBDIR}/libVolumetricAOFilters.so")
vao_expect("${VAO_INCLUDEDIR}/VolumetricAO/vtkVolumetricAmbientOcclusion.h")
vao_expect("${VAO_INCLUDEDIR}/VolumetricAO/VolumetricAOFiltersModule.h")
if(VAO_PLUGIN_INSTALL_FILE)
  vao_expect("${VAO_PLUGIN_INSTALL_FILE}")
endif()

# 3. Configure, build and run the consumer against the installed package only.
set(dependency_args)
if(VAO_PARAVIEW_DIR)
  list(APPEND dependency_args "-DParaView_DIR=${VAO_PARAVIEW_DIR}")
endif()
if(VAO_VTK_DIR)
  list(APPEND dependency_args "-DVTK_DIR=${VAO_VTK_DIR}")
endif()
set(build_type Release)
if(VAO_CONFIG)
  set(build_type "${VAO_CONFIG}")
endif()
vao_run("consumer configure" "${CMAKE_COMMAND}"
  -S "${VAO_CONSUMER_SOURCE_DIR}"
  -B "${VAO_CONSUMER_BINARY_DIR}"
  -G "${VAO_GENERATOR}"
  "-DCMAKE_BUILD_TYPE=${build_type}"
  "-DCMAKE_C_COMPILER=${VAO_C_COMPILER}"
  "-DCMAKE_CXX_COMPILER=${VAO_CXX_COMPILER}"
  "-DCMAKE_PREFIX_PATH=${VAO_INSTALL_PREFIX}"
  # Only the test prefix may provide VolumetricAO (not the build tree, not the
  # user package registry).
  "-DVolumetricAO_DIR=${VAO_INSTALL_PREFIX}/${VAO_LIBDIR}/cmake/VolumetricAO"
  -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF
  ${dependency_args})
vao_run("consumer build" "${CMAKE_COMMAND}" --build "${VAO_CONSUMER_BINARY_DIR}"
  ${config_args})

set(consumer "${VAO_CONSUMER_BINARY_DIR}/vao_consumer")
if(VAO_CONFIG AND EXISTS "${VAO_CONSUMER_BINARY_DIR}/${VAO_CONFIG}/vao_consumer")
  set(consumer "${VAO_CONSUMER_BINARY_DIR}/${VAO_CONFIG}/vao_consumer")
endif()
vao_run("consumer run" "${consumer}")

# 4. The installed plugin loads by itself (no build tree on its RPATH) in pvpython.
if(VAO_PLUGIN_INSTALL_FILE AND VAO_PVPYTHON)
  set(plugin "${VAO_INSTALL_PREFIX}/${VAO_PLUGIN_INSTALL_FILE}")
  set(script "${VAO_CONSUMER_BINARY_DIR}/load_installed_plugin.py")
  file(WRITE "${script}" "
import sys
from paraview.simple import *
LoadPlugin(r'${plugin}', ns=globals())
# The module library must come from the install prefix (the plugin's RPATH), never
# from the build tree.
import os
if os.path.exists('/proc/self/maps'):
    with open('/proc/self/maps') as maps:
        libs = {line.split()[-1] for line in maps if 'libVolumetricAOFilters' in line}
    print('module library loaded from', sorted(libs))
    if not libs or any(not lib.startswith(r'${VAO_INSTALL_PREFIX}/') for lib in libs):
        sys.exit('FAIL: the installed plugin did not load the installed module library')
source = Wavelet()
source.UpdatePipeline()
f = VolumetricAmbientOcclusion(Input=source)
f.Scalars = ['POINTS', 'RTData']
f.Radius = 3
f.UpdatePipeline()
info = f.GetPointDataInformation().GetArray('AmbientOcclusion')
if info is None:
    sys.exit('FAIL: no AmbientOcclusion array from the installed plugin')
print('installed plugin OK, AmbientOcclusion range', info.GetRange())
")
  vao_run("pvpython with the installed plugin" "${VAO_PVPYTHON}" "${script}")
endif()

# 5. The installed Python package, in both interpreters.
if(VAO_PYTHON_DESTINATION)
  vao_expect("${VAO_PYTHON_DESTINATION}/volumetricao/__init__.py")
  find_program(VAO_PYTHON3 python3 PATHS /usr/bin NO_DEFAULT_PATH)
  foreach(interpreter IN ITEMS "${VAO_PYTHON3}" "${VAO_PVPYTHON}")
    if(interpreter)
      vao_run("the installed Python package in ${interpreter}" "${interpreter}" "${VAO_PACKAGE_TEST}"
        "${VAO_INSTALL_PREFIX}/${VAO_PYTHON_DESTINATION}" "${VAO_VERSION}")
    endif()
  endforeach()
endif()

message(STATUS "InstallAndConsume: OK")
