// SPDX-License-Identifier: LGPL-2.1-or-later
// GstDefocusSrc: the `defocussrc` element, the command line's inputs (TUM folders, folder pairs,
// Z16 depth cameras, ...) as two src pads, `color` and `depth`; registered by libgstdefocus.
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

#define GST_TYPE_DEFOCUS_SRC (gst_defocus_src_get_type())
G_DECLARE_FINAL_TYPE(GstDefocusSrc, gst_defocus_src, GST, DEFOCUS_SRC, GstElement)

G_END_DECLS
