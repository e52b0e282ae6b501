// The tile of the scan a block of the normals kernel works from (normal_estimation.cu): the block's pixels
// and the halo around them that their windows reach, loaded into shared memory once, so that each
// window's neighbours are read from there instead of from global memory. TileImage presents the tile as
// the Image pixelNormal() takes, with the scan's own pixel indices, so the normals are computed by the same
// code as without the tile. Eigen-free and host-callable, so that a CPU test checks the tile against the
// whole scan.
#pragma once

#include "core/common/normals.hpp"
#include "elo/device_types.hpp"

namespace elo::cuda {

// A pixel in the tile: its vertex, and 1 where it is usable (non-ground) for normals, else 0. 16 bytes, so
// that a thread reads it from shared memory in one access.
struct alignas(16) TilePixel {
  float x;
  float y;
  float z;
  float usable;
};

// The rows and columns beyond a pixel that its normal reads, for the configured method: the largest
// window's half sizes, or the next row and column for the cross product.
ELO_HOST_DEVICE inline int haloRows(const NormalParams& params) {
  return params.method == NormalMethod::cross_product ? 1 : params.max_window_height / 2;
}
ELO_HOST_DEVICE inline int haloCols(const NormalParams& params) {
  return params.method == NormalMethod::cross_product ? 1 : params.max_window_width / 2;
}

// Which pixels of the image a tile holds: `block_rows` x `block_cols` pixels from (block_row, block_col)
// and the halo around them. Tile rows outside the image hold nothing; tile columns wrap around the image,
// as the windows do.
struct TileShape {
  int rows;  // the image's
  int cols;
  float inverse_cols;  // 1 / cols
  int first_row;       // the image row of tile row 0; negative above the image
  int first_col;       // the image column of tile column 0 before wrapping; negative left of column 0
  int tile_rows;
  int tile_cols;

  ELO_HOST_DEVICE static TileShape around(const NormalParams& params, int block_row, int block_col, int block_rows,
                                          int block_cols) {
    const int halo_rows = haloRows(params);
    const int halo_cols = haloCols(params);
    return {params.rows,          params.cols,
            1.0f / static_cast<float>(params.cols),
            block_row - halo_rows, block_col - halo_cols,
            block_rows + 2 * halo_rows, block_cols + 2 * halo_cols};
  }

  ELO_HOST_DEVICE int slots() const { return tile_rows * tile_cols; }

  // The image pixel that slot `slot` holds; -1 for a row outside the image.
  ELO_HOST_DEVICE int pixelOfSlot(int slot) const {
    const int tile_row = slot / tile_cols;
    const int row = first_row + tile_row;
    if (row < 0 || row >= rows) return -1;
    return row * cols + wrapColumn(first_col + slot - tile_row * tile_cols, cols);
  }

  // The slot that holds image pixel `pixel`, which must lie in a row of the tile and within the halo's
  // columns: every pixel a normal of the block's pixels reads. The row comes from a float quotient, as an
  // integer division costs a GPU some twenty instructions: with fewer than 2^22 tile rows it is off by at
  // most one, which the remainder corrects.
  ELO_HOST_DEVICE int slotOfPixel(int pixel) const {
    const int from_first_row = pixel - first_row * cols;
    int tile_row = static_cast<int>(static_cast<float>(from_first_row) * inverse_cols);
    int col = from_first_row - tile_row * cols;
    if (col < 0) {
      --tile_row;
      col += cols;
    } else if (col >= cols) {
      ++tile_row;
      col -= cols;
    }
    // A tile narrower than the image holds each column once; a wider one holds some twice, alike.
    return tile_row * tile_cols + wrapColumn(col - first_col, cols);
  }
};

// The tile as the Image of normals.hpp: the scan's rows, columns and pixel indices; vertices and labels
// from the tile, the centre's range (all pixelNormal() reads of it) from the scan.
struct TileImage {
  int rows;
  int cols;
  TileShape shape;
  const TilePixel* pixels;
  const float* ranges;

  ELO_HOST_DEVICE bool usable(int pixel) const { return pixels[shape.slotOfPixel(pixel)].usable != 0.0f; }
  ELO_HOST_DEVICE Float3 vertex(int pixel) const {
    const TilePixel& p = pixels[shape.slotOfPixel(pixel)];
    return {p.x, p.y, p.z};
  }
  ELO_HOST_DEVICE float range(int pixel) const { return ranges[pixel]; }
};

// What slot `slot` of the tile holds, from an Image of normals.hpp over the whole scan.
template <typename Image>
ELO_HOST_DEVICE TilePixel loadTilePixel(const Image& image, const TileShape& shape, int slot) {
  const int pixel = shape.pixelOfSlot(slot);
  if (pixel < 0 || !image.usable(pixel)) return {0.0f, 0.0f, 0.0f, 0.0f};
  const Float3 vertex = image.vertex(pixel);
  return {vertex.x, vertex.y, vertex.z, 1.0f};
}

}  // namespace elo::cuda
