// SPDX-License-Identifier: LGPL-2.1-or-later
// GstDefocus: the `defocus` element (GstVideoAggregator), registered by the plugin libgstdefocus.
#pragma once

#include <gst/gst.h>
#include <gst/video/gstvideoaggregator.h>
#include <gst/video/video.h>

G_BEGIN_DECLS

#define GST_TYPE_DEFOCUS (gst_defocus_get_type())
G_DECLARE_FINAL_TYPE(GstDefocus, gst_defocus, GST, DEFOCUS, GstVideoAggregator)

G_END_DECLS
