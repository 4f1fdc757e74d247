// SPDX-License-Identifier: LGPL-2.1-or-later
// Run and machine description, and the statistics, for defocus-bench and defocus-bench-accuracy.
#include "samples/BenchMachine.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <fstream>

namespace defocus {

std::string utcNow()
{
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return text;
}

std::string cpuModel()
{
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line))
        if (line.rfind("model name", 0) == 0)
            if (const auto colon = line.find(':'); colon != std::string::npos)
                return line.substr(line.find_first_not_of(' ', colon + 1));
    return "unknown";
}

double quantile(std::vector<double> values, double q)
{
    if (values.empty())
        return std::nan("");
    std::sort(values.begin(), values.end());
    const double position = q * static_cast<double>(values.size() - 1);
    const auto below = static_cast<std::size_t>(std::floor(position));
    const std::size_t above = std::min(below + 1, values.size() - 1);
    const double t = position - static_cast<double>(below);
    return values[below] + (values[above] - values[below]) * t;
}

double median(const std::vector<double>& values)
{
    return quantile(values, 0.5);
}

double p90(const std::vector<double>& values)
{
    return quantile(values, 0.9);
}

} // namespace defocus
