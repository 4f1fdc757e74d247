// SPDX-License-Identifier: LGPL-2.1-or-later
// The exit statuses every defocus program returns, one table for all of them (README, "Exit
// status"). A batch runner reads them: 1 and 2 will fail again on the same input, 75 and the
// signal statuses are worth a retry.
#pragma once

namespace defocus {

enum ExitStatus : int {
    kExitDone = 0,         ///< every frame in gave a frame out
    kExitBadInput = 1,     ///< an input or output file or device that cannot work, or a request the input
                           ///< cannot meet (one image from several frames): do not retry
    kExitUsage = 2,        ///< the command line (any parse or range error, options that do not go
                           ///< together, an --egl-device the machine does not have)
    kExitUnavailable = 75, ///< no EGL display / GL 4.5 context, or a busy device (sysexits' EX_TEMPFAIL): retry
    kExitInterrupted = 130,///< Ctrl-C (128 + SIGINT); nothing under the output's name (defocus --keep-partial: OUTPUT.partial)
    kExitTerminated = 143, ///< SIGTERM (128 + SIGTERM), as a scheduler sends at a time limit; as Ctrl-C
};

} // namespace defocus
