# AERIE_BUILD_FUZZ (docs/fuzz.md, scripts/fuzz.sh): with clang, every target of the project is
# compiled with libFuzzer's coverage instrumentation and ASan + UBSan (a UBSan report aborts),
# so that the fuzz targets of fuzz/ see into the libraries they call and stop at the first
# sanitizer report. The fuzz targets themselves link -fsanitize=fuzzer (fuzz/CMakeLists.txt).
# Included by the top-level CMakeLists.txt before any target is defined.
set(AERIE_FUZZ_LIBFUZZER OFF)
if(AERIE_BUILD_FUZZ)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    set(AERIE_FUZZ_LIBFUZZER ON)
    set(ignorelist ${CMAKE_CURRENT_LIST_DIR}/coverage_ignorelist.txt)
    add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                        -fno-omit-frame-pointer -fsanitize-coverage-ignorelist=${ignorelist})
    # Clang's dependency files do not name the list: its hash in every object's flags makes an
    # edit reconfigure and compile them again.
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${ignorelist})
    file(SHA1 ${ignorelist} ignorelist_hash)
    string(SUBSTRING ${ignorelist_hash} 0 12 ignorelist_hash)
    add_compile_definitions(AERIE_FUZZ_IGNORELIST=${ignorelist_hash})
    add_link_options(-fsanitize=address,undefined)
  else()
    message(WARNING "AERIE_BUILD_FUZZ needs clang (libFuzzer); with ${CMAKE_CXX_COMPILER_ID} only the "
                    "replay drivers of fuzz/ are built. Configure with -DCMAKE_CXX_COMPILER=clang++ "
                    "-DCMAKE_C_COMPILER=clang (scripts/fuzz.sh does).")
  endif()
endif()
