# Warning flags live in one INTERFACE target that every evio target links
# privately; no global flags are set.
add_library(evio_warnings INTERFACE)
add_library(evio::warnings ALIAS evio_warnings)
target_compile_options(evio_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align
  -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2
  -Wimplicit-fallthrough)
if(EVIO_WARNINGS_AS_ERRORS)
  target_compile_options(evio_warnings INTERFACE -Werror)
endif()
target_compile_features(evio_warnings INTERFACE cxx_std_20)
# No contraction of a*b+c into FMA, whatever -march says: the renderer's AVX2
# and baseline paths (and the 8-lane texture lookups) must round every
# product and sum alike to render the same bits (renderer_test.cpp).
target_compile_options(evio_warnings INTERFACE -ffp-contract=off)
