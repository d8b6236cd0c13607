# Debian packages by CPack (`cpack -G DEB` in a build directory; scripts/deb-test builds, installs
# and checks them on a clean Debian 12):
#   libkelp-dev   the headers, the CMake package (find_package(kelp)), the compiled kelp::sim
#                 library and the vehicle files            (install component `dev`)
#   kelp-tools    the programs, their plotting scripts, scenarios, sweeps, the replay page's
#                 template and the SITL parameter files    (components `tools` and `sitl`)
#   python3-kelp  the `kelp` Python package                (component `python`)
# Configure with -DCMAKE_INSTALL_PREFIX=/usr and -DKELP_PYTHON_INSTALL_DIR=lib/python3/dist-packages
# (Debian's path for python3's packages), as scripts/deb-test does. The programs' and the Python
# module's shared-library dependencies are found by dpkg-shlibdeps; the rest are listed here.
set(CPACK_PACKAGE_NAME kelp)
set(CPACK_PACKAGE_VENDOR "the kelp authors")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Dynamics of tethered marine robots")
set(CPACK_PACKAGE_CONTACT "the kelp authors <kelp@localhost>")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX ${CMAKE_INSTALL_PREFIX})
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ONE_PER_GROUP)
set(CPACK_COMPONENTS_ALL dev tools sitl python)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://arxiv.org/abs/2508.02264")

set(CPACK_DEBIAN_LIBKELP-DEV_PACKAGE_NAME libkelp-dev)
set(CPACK_DEBIAN_KELP-TOOLS_PACKAGE_NAME kelp-tools)
set(CPACK_DEBIAN_PYTHON3-KELP_PACKAGE_NAME python3-kelp)
# libkelp-dev: Eigen for every consumer; a C++ compiler, CMake and a build tool to use it (cmake
# only recommends make); tinyxml2, which a static kelp::sim links (its SDF importer).
set(CPACK_DEBIAN_LIBKELP-DEV_PACKAGE_DEPENDS
    "libeigen3-dev (>= 3.4), libtinyxml2-dev, g++ | c++-compiler, cmake (>= 3.16), make | ninja-build")
set(CPACK_DEBIAN_LIBKELP-DEV_PACKAGE_SUGGESTS "libceres-dev, kelp-tools, python3-kelp")
# kelp-tools: plot_run.py and plot_sweep.py run on Debian's python3 with matplotlib.
set(CPACK_DEBIAN_KELP-TOOLS_PACKAGE_DEPENDS "python3")
set(CPACK_DEBIAN_KELP-TOOLS_PACKAGE_RECOMMENDS "python3-matplotlib, python3-munkres")
# python3-kelp: the module is built for this python3 (its ABI tag in the file name).
if(DEFINED Python_EXECUTABLE)
  execute_process(COMMAND ${Python_EXECUTABLE} -c "import sys; print(sys.version_info[1])"
                  OUTPUT_VARIABLE py_minor OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE py_rc)
endif()
if(DEFINED Python_EXECUTABLE AND py_rc EQUAL 0)
  math(EXPR next_minor "${py_minor} + 1")
  set(CPACK_DEBIAN_PYTHON3-KELP_PACKAGE_DEPENDS
      "python3 (>= 3.${py_minor}), python3 (<< 3.${next_minor}), python3-numpy")
else()
  set(CPACK_DEBIAN_PYTHON3-KELP_PACKAGE_DEPENDS "python3, python3-numpy")
endif()

# After every CPACK_ variable: include(CPack) writes them into CPackConfig.cmake.
include(CPack)

cpack_add_component_group(libkelp-dev DESCRIPTION
  "kelp: headers, CMake package and the compiled simulation library (kelp::sim)")
cpack_add_component_group(kelp-tools DESCRIPTION
  "kelp: kelp-tethered-pair, kelp-sweep, kelp-sitl, kelp-mission, kelp-replay and their data")
cpack_add_component_group(python3-kelp DESCRIPTION "kelp: the Python package (import kelp)")
cpack_add_component(dev GROUP libkelp-dev)
cpack_add_component(tools GROUP kelp-tools)
cpack_add_component(sitl GROUP kelp-tools)
cpack_add_component(python GROUP python3-kelp)
