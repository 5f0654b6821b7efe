# Finds CHOLMOD, SuiteSparseQR, AMD and CAMD as packaged by Debian 12 (libsuitesparse-dev 5.12), which
# ships headers in /usr/include/suitesparse and no CMake package files. Defines SuiteSparse::CHOLMOD and
# SuiteSparse::SPQR, linked against OpenBLAS (LAPACK/BLAS) and METIS through the shared libraries, and
# SuiteSparse::AMD and SuiteSparse::CAMD (BSD-3; the orders of src/linalg/symbolic.h, which call them directly).
find_path(SUITESPARSE_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_path(AMD_INCLUDE_DIR amd.h PATH_SUFFIXES suitesparse)
find_path(CAMD_INCLUDE_DIR camd.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
find_library(SPQR_LIBRARY spqr)
find_library(AMD_LIBRARY amd)
find_library(CAMD_LIBRARY camd)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparseLibs DEFAULT_MSG
  SUITESPARSE_INCLUDE_DIR CHOLMOD_LIBRARY SPQR_LIBRARY AMD_INCLUDE_DIR AMD_LIBRARY CAMD_INCLUDE_DIR CAMD_LIBRARY
  SUITESPARSECONFIG_LIBRARY)
if(SuiteSparseLibs_FOUND AND NOT TARGET SuiteSparse::CHOLMOD)
  add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES IMPORTED_LOCATION ${CHOLMOD_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${SUITESPARSE_INCLUDE_DIR}
    INTERFACE_LINK_LIBRARIES ${SUITESPARSECONFIG_LIBRARY})
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
