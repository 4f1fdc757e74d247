// SPDX-License-Identifier: LGPL-2.1-or-later
// File names (sources/PathNames): extensions in any case, video files by extension, and the
// natural order by which colour and depth folders are paired frame by frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "sources/PathNames.hpp"

namespace defocus {
namespace {

bool less(const std::string& a, const std::string& b)
{
    return naturalLess(a, b);
}

// Defect caught: numbered frames in plain string order ("f10" before "f2"), which pairs frame 10's
// colour with frame 2's depth, or leading zeros counted as value.
TEST(PathNames, NumberedNamesSortByNumber)
{
    EXPECT_TRUE(less("frame2.png", "frame10.png"));
    EXPECT_FALSE(less("frame10.png", "frame2.png"));
    EXPECT_TRUE(less("f007.png", "f10.png"));
    EXPECT_TRUE(less("a9b", "a10a"));
    EXPECT_TRUE(less("x", "x1"));
    std::vector<std::string> names{"d10.png", "d9.png", "d100.png", "d1.png", "d0.png"};
    std::sort(names.begin(), names.end(), less);
    EXPECT_EQ(names, (std::vector<std::string>{"d0.png", "d1.png", "d9.png", "d10.png", "d100.png"}));
}

// Defect caught: names equal by value ("f1" and "f01") compared as neither before the other, so
// std::sort leaves them in the order the folder listed them: a colour folder and a depth folder
// listed in different orders pair the wrong files, and a rerun may pair them differently.
TEST(PathNames, NamesEqualByValueStillHaveOneOrder)
{
    EXPECT_NE(less("f1.png", "f01.png"), less("f01.png", "f1.png"));
    std::vector<std::string> names{"f1.png", "f01.png", "f001.png", "f2.png"};
    std::sort(names.begin(), names.end(), less);
    const std::vector<std::string> sorted = names;
    std::sort(names.begin(), names.end());
    do {
        std::vector<std::string> listed = names;
        std::sort(listed.begin(), listed.end(), less);
        EXPECT_EQ(listed, sorted);
    } while (std::next_permutation(names.begin(), names.end()));
}

// Defect caught: an order std::sort cannot use (not irreflexive, not transitive), which is
// undefined behaviour there, or one that is not total on distinct names.
TEST(PathNames, NaturalOrderIsAStrictTotalOrder)
{
    const std::vector<std::string> names{"",     "0",     "00",    "1",   "01",   "10",  "a",    "a0",   "a00",
                                         "a1",   "a01",   "a1b",   "a01b", "a1c", "a2",   "a10", "a10b", "b",
                                         "B",    "_1",    "1a",    "01a",  "9",   "a9z", "a09", "\xc3\xa9"};
    for (const std::string& a : names) {
        EXPECT_FALSE(less(a, a)) << a;
        for (const std::string& b : names) {
            if (a != b) {
                EXPECT_NE(less(a, b), less(b, a)) << a << " vs " << b;
            }
            for (const std::string& c : names) {
                if (less(a, b) && less(b, c)) {
                    EXPECT_TRUE(less(a, c)) << a << " < " << b << " < " << c;
                }
            }
        }
    }
}

// Defect caught: characters compared as signed bytes, which puts UTF-8 names ("é") before ASCII
// ones, unlike std::string and `ls` in the C locale; names without digits must sort as strings.
TEST(PathNames, NamesWithoutDigitsSortAsPlainStrings)
{
    std::vector<std::string> names{"\xc3\xa9t\xc3\xa9.png", "zebra.png", "Apple.png", "apple.png", "_x.png", "a.png"};
    std::vector<std::string> natural = names;
    std::sort(natural.begin(), natural.end(), less);
    std::sort(names.begin(), names.end());
    EXPECT_EQ(natural, names);
}

// Defect caught: an extension compared in the case it was typed, so "CLIP.MP4" or "DEPTH.TXT" is
// not recognised as what it is.
TEST(PathNames, ExtensionsInAnyCase)
{
    EXPECT_EQ(lowerExtension("clip.MP4"), ".mp4");
    EXPECT_EQ(lowerExtension("dir.D/Depth.TxT"), ".txt");
    EXPECT_EQ(lowerExtension("archive.tar.GZ"), ".gz");
    EXPECT_EQ(lowerExtension("rgb"), "");
    EXPECT_EQ(lowerExtension(".hidden"), "");
    EXPECT_EQ(lowerExtension("photo.\xc3\x89XR"), ".\xc3\x89xr"); // bytes beyond ASCII stay as they are
    EXPECT_TRUE(isVideoFile("CLIP.MOV"));
    EXPECT_TRUE(isVideoFile("a/b.webm"));
    EXPECT_TRUE(isVideoFile("take.M4v"));
    EXPECT_FALSE(isVideoFile("a.mp4.png"));
    EXPECT_FALSE(isVideoFile("mp4"));
    EXPECT_FALSE(isVideoFile("a.mp4/"));
}

} // namespace
} // namespace defocus
