# Finds CHOLMOD and SuiteSparseQR as packaged by Debian 12 (libsuitesparse-dev 5.12), which ships
# headers in /usr/include/suitesparse and no CMake package files. Defines SuiteSparse::CHOLMOD and
# SuiteSparse::SPQR, linked against OpenBLAS (LAPACK/BLAS) and METIS through the shared libraries.
find_path(SUITESPARSE_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse)
find_library(CHOLMOD_LIBRARY cholmod)
find_library(SPQR_LIBRARY spqr)
find_library(SUITESPARSECONFIG_LIBRARY suitesparseconfig)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(SuiteSparseLibs DEFAULT_MSG
  SUITESPARSE_INCLUDE_DIR CHOLMOD_LIBRARY SPQR_LIBRARY SUITESPARSECONFIG_LIBRARY)
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
