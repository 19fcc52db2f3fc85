#include "case/semver.hpp"

#include <gtest/gtest.h>

namespace viscera::vcase {
namespace {

TEST(VcaseSemVer, ParsesCoreFieldsPrereleaseAndBuild) {
    auto v = SemVer::parse("1.20.3-rc.1+build.7");
    ASSERT_TRUE(v);
    EXPECT_EQ(v->major, 1u);
    EXPECT_EQ(v->minor, 20u);
    EXPECT_EQ(v->patch, 3u);
    EXPECT_EQ(v->prerelease, "rc.1");
    EXPECT_EQ(v->build, "build.7");
    EXPECT_EQ(v->toString(), "1.20.3-rc.1+build.7");
}

TEST(VcaseSemVer, RejectsMalformedVersions) {
    for (const char* text :
         {"", "1", "1.2", "1.2.3.4", "v1.2.3", "01.2.3", "1.02.3", "1.2.03", "1.2.3-", "1.2.3-a..b", "1.2.3-01",
          "1.2.3+", "1.2.3-a_b", "a.b.c", " 1.2.3", "1.2.3 ", "-1.2.3", "99999999999999999999.0.0"})
        EXPECT_FALSE(SemVer::parse(text)) << text;
    EXPECT_TRUE(SemVer::parse("1.2.3-0.a-b"));
    EXPECT_TRUE(SemVer::parse("1.2.3+001"));
}

TEST(VcaseSemVer, PrecedenceFollowsTheSpecificationExample) {
    // semver.org §11: 1.0.0-alpha < 1.0.0-alpha.1 < 1.0.0-alpha.beta < 1.0.0-beta
    //                 < 1.0.0-beta.2 < 1.0.0-beta.11 < 1.0.0-rc.1 < 1.0.0
    const char* ordered[] = {"1.0.0-alpha", "1.0.0-alpha.1", "1.0.0-alpha.beta",
                             "1.0.0-beta",  "1.0.0-beta.2",  "1.0.0-beta.11",
                             "1.0.0-rc.1",  "1.0.0",         "1.0.1",
                             "1.1.0",       "2.0.0",         "10.0.0"};
    const size_t n = std::size(ordered);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j) {
            auto a = *SemVer::parse(ordered[i]), b = *SemVer::parse(ordered[j]);
            EXPECT_EQ(compare(a, b), i <=> j) << ordered[i] << " vs " << ordered[j];
        }
}

TEST(VcaseSemVer, BuildMetadataDoesNotAffectPrecedence) {
    EXPECT_EQ(compare(*SemVer::parse("1.0.0+a"), *SemVer::parse("1.0.0+b")), std::strong_ordering::equal);
}

TEST(VcaseSemVer, PlayerVersionIsTheBuildVersion) {
    EXPECT_EQ(playerVersion().toString(), VISCERA_VERSION);
}

} // namespace
} // namespace viscera::vcase
