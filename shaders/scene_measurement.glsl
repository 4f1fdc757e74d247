// The layout of the scene analysis' measurement of a frame: scene_analysis.comp writes it,
// highlights.glsl reads it in place, filter/passes/SceneAnalysisPass.cpp reads it back (keep its
// kWordsPerTile in step). Per tile of kTileSize^2 pixels, rows of tiles top to bottom,
// kMeasurementWords words.
const int kTileSize = 16;
const int kMeasurementWords = 13;
const int kMinDepthWord = 0;   // float bits, metres
const int kMaxDepthWord = 1;   // float bits, metres
const int kFirstReachWord = 2; // 8 words: the pixels with |CoC| >= each histogram edge
const int kHighlightsWord = 10; // pixels above white (float) or with a channel >= 250 (8-bit)
const int kPixelsWord = 11;
const int kLuminanceWord = 12; // float bits: the pixels' luminance summed

// The first word of the tile holding `texel` in a frame `frameSize` wide and high.
int measurementBase(ivec2 texel, ivec2 frameSize)
{
    const int tilesX = (frameSize.x + kTileSize - 1) / kTileSize;
    return kMeasurementWords * ((texel.y / kTileSize) * tilesX + texel.x / kTileSize);
}
