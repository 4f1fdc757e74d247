// SPDX-License-Identifier: LGPL-2.1-or-later
// Small helpers for talking to a V4L2 device node, shared by the camera source and the
// virtual-camera sink.
#pragma once

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <string>
#include <system_error>

#include <linux/types.h>
#include <sys/ioctl.h>

namespace defocus::v4l2 {

/// ioctl, retried when a signal interrupts it.
inline int xioctl(int fd, unsigned long request, void* arg)
{
    int result = 0;
    do
        result = ::ioctl(fd, request, arg);
    while (result == -1 && errno == EINTR);
    return result;
}

/// strerror's text for `error`, thread-safe.
inline std::string errorText(int error)
{
    return std::system_category().message(error);
}

/// The driver's fixed-size string fields (card, driver) as a std::string.
template <std::size_t N>
std::string fieldText(const __u8 (&field)[N])
{
    const auto* begin = reinterpret_cast<const char*>(field);
    return std::string(begin, strnlen(begin, N));
}

} // namespace defocus::v4l2
