// The translation unit that carries the precompiled <gtest/gtest.h> every GoogleTest file reuses
// (cmake/CalfTargets.cmake, calf_test_pch); it defines nothing.
