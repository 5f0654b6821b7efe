# SPDX-License-Identifier: MIT
# Finds AMD and CAMD (BSD-3; the orders of src/linalg/symbolic.h, which call them directly) and, as the
# components CHOLMOD and SPQR, CHOLMOD and SuiteSparseQR (GPL; only a build with TRIVCON_WITH_SUITESPARSE asks
# for them), as packaged by Debian 12 (libsuitesparse-dev 5.12), which ships headers in /usr/include/suitesparse
# and no CMake package files. Defines SuiteSparse::AMD and SuiteSparse::CAMD, and with the components
# SuiteSparse::CHOLMOD and SuiteSparse::SPQR, linked against OpenBLAS (LAPACK/BLAS) and METIS through the shared
# libraries.
find_path(AMD_INCLUDE_DIR amd.h PATH_SUFFIXES suitesparse)
find_path(CAMD_INCLUDE_DIR camd.h PATH_SUFFIXES suitesparse)
find_library(AMD_LIBRARY amd)
find_library(CAMD_LIBRARY camd)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
set(_suitesparse_required AMD_INCLUDE_DIR AMD_LIBRARY CAMD_INCLUDE_DIR CAMD_LIBRARY SUITESPARSECONFIG_LIBRARY)
if("CHOLMOD" IN_LIST SuiteSparseLibs_FIND_COMPONENTS OR "SPQR" IN_LIST SuiteSparseLibs_FIND_COMPONENTS)
  find_path(SUITESPARSE_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
  find_library(CHOLMOD_LIBRARY cholmod)
  find_library(SPQR_LIBRARY spqr)
  list(APPEND _suitesparse_required SUITESPARSE_INCLUDE_DIR CHOLMOD_LIBRARY)
  if("SPQR" IN_LIST SuiteSparseLibs_FIND_COMPONENTS)
    list(APPEND _suitesparse_required SPQR_LIBRARY)
  endif()
endif()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparseLibs DEFAULT_MSG ${_suitesparse_required})
if(SuiteSparseLibs_FOUND AND CHOLMOD_LIBRARY AND NOT TARGET SuiteSparse::CHOLMOD)
  add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES IMPORTED_LOCATION ${CHOLMOD_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${SUITESPARSE_INCLUDE_DIR}
    INTERFACE_LINK_LIBRARIES ${SUITESPARSECONFIG_LIBRARY})
endif()
if(SuiteSparseLibs_FOUND AND SPQR_LIBRARY AND NOT TARGET SuiteSparse::SPQR)
  add_library(SuiteSparse::SPQR UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::SPQR PROPERTIES IMPORTED_LOCATION ${SPQR_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${SUITESPARSE_INCLUDE_DIR}
    INTERFACE_LINK_LIBRARIES "SuiteSparse::CHOLMOD")
endif()
if(SuiteSparseLibs_FOUND AND NOT TARGET SuiteSparse::AMD)
  add_library(SuiteSparse::AMD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::AMD PROPERTIES IMPORTED_LOCATION ${AMD_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${AMD_INCLUDE_DIR}
    INTERFACE_LINK_LIBRARIES ${SUITESPARSECONFIG_LIBRARY})
  add_library(SuiteSparse::CAMD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::CAMD PROPERTIES IMPORTED_LOCATION ${CAMD_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${CAMD_INCLUDE_DIR}
    INTERFACE_LINK_LIBRARIES ${SUITESPARSECONFIG_LIBRARY})
endif()
