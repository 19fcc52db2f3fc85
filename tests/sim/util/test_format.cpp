#include "sim/util/format.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

using viscera::sim::formatNumber;

TEST(FormatNumber, IsPrintfG) {
    for (double v : {0.0, -0.0, 1.0, 0.1, 1e-9, 123456789.0, -2.5e300, 3.14159265358979, 1e6, 999999.5,
                     std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::denorm_min()})
        for (int digits : {1, 3, 4, 6, 12, 17}) {
            char expected[64];
            std::snprintf(expected, sizeof expected, "%.*g", digits, v);
            EXPECT_EQ(formatNumber(v, digits), expected) << v << " with " << digits << " digits";
        }
    EXPECT_EQ(formatNumber(0.000123456789), "0.000123457"); // 6 digits by default
    EXPECT_EQ(formatNumber(1e6), "1e+06");
}

TEST(FormatNumber, NanHasNoSign) {
    EXPECT_EQ(formatNumber(std::nan("")), "nan");
    EXPECT_EQ(formatNumber(-std::nan(""), 12), "nan");
}

TEST(FormatNumber, LongPrecisionIsNotCut) {
    char expected[512];
    std::snprintf(expected, sizeof expected, "%.60g", 0.1);
    EXPECT_EQ(formatNumber(0.1, 60), expected);
}
