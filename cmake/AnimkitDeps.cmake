# Third-party libraries, all from Debian packages (scripts/install-deps.sh installs them).
# Each is linked by its plain name so the installed pkg-config file and CMake package stay
# relocatable.
set(AK_DEP_INCLUDE_DIRS "")

function(ak_require_lib var libname header pkg)
  find_library(${var}_PATH NAMES ${libname})
  find_path(${var}_INC NAMES ${header} PATH_SUFFIXES suitesparse assimp cjson)
  if(NOT ${var}_PATH OR NOT ${var}_INC)
    message(FATAL_ERROR "animkit needs ${libname} (${header}); install the Debian package "
                        "${pkg}, or run: sudo scripts/install-deps.sh")
  endif()
  set(${var} ${libname} PARENT_SCOPE)
  set(AK_DEP_INCLUDE_DIRS ${AK_DEP_INCLUDE_DIRS} ${${var}_INC} PARENT_SCOPE)
endfunction()

set(THREADS_PREFER_PTHREAD_FLAG ON)
find_package(Threads REQUIRED)
set(AK_THREAD_LIBS pthread)
ak_require_lib(AK_PNG_LIBS png png.h libpng-dev)
ak_require_lib(AK_GIF_LIBS gif gif_lib.h libgif-dev)
ak_require_lib(AK_ASSIMP_LIBS assimp assimp/cimport.h libassimp-dev)
ak_require_lib(AK_CJSON_LIBS cjson cjson/cJSON.h libcjson-dev)
ak_require_lib(AK_CHOLMOD_LIBS cholmod cholmod.h libsuitesparse-dev)
# Optional: JPEG textures in glTF/OBJ models (Debian libjpeg62-turbo-dev). Without it the io
# module still builds; a JPEG image is then a warning and the mesh is drawn untextured.
find_library(AK_JPEG_LIBS_PATH NAMES jpeg)
find_path(AK_JPEG_LIBS_INC NAMES jpeglib.h)
if(AK_JPEG_LIBS_PATH AND AK_JPEG_LIBS_INC)
  set(AK_JPEG_LIBS jpeg)
  set(AK_HAVE_JPEG ON)
  list(APPEND AK_DEP_INCLUDE_DIRS ${AK_JPEG_LIBS_INC})
else()
  set(AK_JPEG_LIBS "")
  set(AK_HAVE_JPEG OFF)
  message(STATUS "animkit: libjpeg not found (Debian libjpeg62-turbo-dev): JPEG textures are skipped with a warning")
endif()
list(REMOVE_DUPLICATES AK_DEP_INCLUDE_DIRS)
