// SPDX-License-Identifier: LGPL-2.1-or-later
// File names: extensions in lower case, video clips by extension, natural order.
#include "sources/PathNames.hpp"

#include <algorithm>
#include <array>

namespace defocus {
namespace {

bool isDigit(char c)
{
    return c >= '0' && c <= '9';
}

char lower(char c)
{
    return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
}

} // namespace

std::string lowerExtension(const std::filesystem::path& file)
{
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), lower);
    return ext;
}

bool isVideoFile(const std::filesystem::path& file)
{
    static constexpr std::array<std::string_view, 6> extensions = {".mp4", ".avi", ".mkv",
                                                                   ".mov", ".m4v", ".webm"};
    return std::find(extensions.begin(), extensions.end(), lowerExtension(file)) != extensions.end();
}

bool naturalLess(std::string_view a, std::string_view b)
{
    std::size_t i = 0;
    std::size_t j = 0;
    while (i < a.size() && j < b.size()) {
        if (isDigit(a[i]) && isDigit(b[j])) {
            std::size_t iEnd = i;
            std::size_t jEnd = j;
            while (iEnd < a.size() && isDigit(a[iEnd]))
                ++iEnd;
            while (jEnd < b.size() && isDigit(b[jEnd]))
                ++jEnd;
            // The runs without their leading zeros: the longer is larger, else the first digit
            // that differs decides.
            std::string_view x = a.substr(i, iEnd - i);
            std::string_view y = b.substr(j, jEnd - j);
            x.remove_prefix(std::min(x.find_first_not_of('0'), x.size()));
            y.remove_prefix(std::min(y.find_first_not_of('0'), y.size()));
            if (x.size() != y.size())
                return x.size() < y.size();
            if (x != y)
                return x < y;
            i = iEnd;
            j = jEnd;
        } else {
            if (a[i] != b[j]) // as bytes, as std::string orders them: UTF-8 after ASCII
                return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
            ++i;
            ++j;
        }
    }
    if (a.size() - i != b.size() - j)
        return a.size() - i < b.size() - j;
    return a < b; // equal by value ("f01" and "f1"): the plain strings decide
}

} // namespace defocus
