# GoogleTest -> GTest::gtest_main, GTest::gmock
find_package(GTest REQUIRED)
include(GoogleTest)
