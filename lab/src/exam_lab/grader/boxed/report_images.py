"""The pictures of a report, for OCR, as the report reader's box's uid: PIL only (Debian's python3-pil).

Where a text page's pictures stand (:func:`picture_regions`: the ink of the page's image that no word
of its text layer explains), each cut out with the text layer's words painted out (:func:`cut_out`),
and prepared for tesseract: a terminal's screenshot is light on dark, which tesseract reads poorly
(underscores lost, ``0.778`` as ``0.7/8``), so it is inverted, grayscaled, enlarged and stretched
(:func:`prepare_picture`). No I/O but the image files the reader names.
"""
from PIL import Image, ImageDraw, ImageFilter, ImageOps


class PictureError(Exception):
    """A picture that cannot be opened, or too large to be (a decompression bomb): said, not read."""


def open_image(path, max_pixels):
    """The image at ``path``, loaded, of at most ``max_pixels`` pixels; raises :class:`PictureError`."""
    Image.MAX_IMAGE_PIXELS = None  # PIL's own check refuses before its size is known: this one says it
    try:
        image = Image.open(path)
        width, height = image.size
        if width * height > max_pixels:
            raise PictureError('a picture of %d x %d pixels (at most %d million)' % (width, height, max_pixels // 10 ** 6))
        image.load()
        return image
    except (OSError, SyntaxError, ValueError, Image.DecompressionBombError) as err:
        raise PictureError('the picture cannot be read: %s' % err)


def preview(image, pixels):
    """A copy of ``image`` whose longest side is at most ``pixels``, in RGB or gray."""
    copy = image.convert('RGB') if image.mode not in ('RGB', 'L') else image.copy()
    copy.thumbnail((pixels, pixels))
    return copy


def dark(image):
    """Whether ``image`` (gray) is mostly dark: light text on a dark background."""
    histogram = image.histogram()
    total = sum(histogram) or 1
    return sum(i * n for i, n in enumerate(histogram)) / float(total) < 110


def prepare_picture(image, text_pixels=2000, most=3):
    """A picture (a screenshot) made what tesseract reads best: gray, dark text on light (inverted when
    light on dark), enlarged twice (a screenshot's text is 12-16 pixels high; tesseract reads 30 best)
    when that keeps it under ``text_pixels`` wide, stretched to full contrast, padded. Not thresholded:
    a threshold drops the underscores of ``/pressure_remote`` (measured on the fixtures' screenshots)."""
    gray = ImageOps.grayscale(image) if image.mode != 'L' else image
    if dark(gray):
        gray = ImageOps.invert(gray)
    factor = max(1.0, min(float(most), 2.0, text_pixels / float(max(1, gray.size[0]))))
    if factor > 1.01:
        gray = gray.resize((int(gray.size[0] * factor), int(gray.size[1] * factor)), Image.LANCZOS)
    return ImageOps.expand(ImageOps.autocontrast(gray), border=20, fill=255)


def prepare_page(image):
    """A page rendered without text (a scan): gray, dark on light, its speckles taken out (a median
    filter: tesseract's mean confidence on the fixtures' scan 81 -> 92, and faster); tesseract
    binarizes it itself."""
    gray = ImageOps.grayscale(image) if image.mode != 'L' else image
    return (ImageOps.invert(gray) if dark(gray) else gray).filter(ImageFilter.MedianFilter(3))


def underscore_between(image, left, right, ink=128, share=0.7):
    """Whether the gap between two words of a line (tesseract's boxes ``(left, top, width, height)`` in
    the prepared ``image``) holds an underscore: a run of ink along the line's bottom across most of the
    gap, where a space holds none."""
    x0, x1 = left[0] + left[2], right[0]
    if x1 - x0 < 2 or x1 - x0 > 2 * max(left[3], right[3]):
        return False
    top = min(left[1], right[1])
    bottom = max(left[1] + left[3], right[1] + right[3])
    height = bottom - top
    y0, y1 = top + height // 2, min(image.size[1], bottom + height // 4)
    pixels = image.load()
    inked = sum(1 for x in range(x0 + 1, x1 - 1) if any(pixels[x, y] < ink for y in range(y0, y1)))
    return inked >= share * max(1, x1 - x0 - 2)


def picture_regions(page, boxes, page_width, min_inches=(0.8, 0.25), min_ink=0.2, cell=8, white=230):
    """Where a text page's pictures stand: ``[(x0, y0, x1, y1)]`` in points, top first.

    :param page: the page's image (any mode, any scale).
    :param boxes: the text layer's words ``(x0, y0, x1, y1)`` in points: their ink is not a picture's.
    :param page_width: the page's width in points (its image's scale).
    :param min_inches: the least width and height of a picture (a rule, a bullet is not one).
    :param min_ink: the least share of a picture's cells that hold ink (a table's border is mostly empty).
    """
    gray = ImageOps.grayscale(page) if page.mode != 'L' else page.copy()
    scale = gray.size[0] / float(page_width)
    draw = ImageDraw.Draw(gray)
    for x0, y0, x1, y1 in boxes:
        draw.rectangle([x0 * scale - 1, y0 * scale - 1, x1 * scale + 1, y1 * scale + 1], fill=255)
    cols, rows = max(1, gray.size[0] // cell), max(1, gray.size[1] // cell)
    grid = gray.resize((cols, rows), Image.BOX).load()
    ink = [[grid[c, r] < white for c in range(cols)] for r in range(rows)]
    grown = [[any(ink[rr][cc] for rr in range(max(0, r - 1), min(rows, r + 2)) for cc in range(max(0, c - 1), min(cols, c + 2)))
              for c in range(cols)] for r in range(rows)]
    seen = [[False] * cols for _ in range(rows)]
    regions, cell_points = [], cell / scale
    for r in range(rows):
        for c in range(cols):
            if not grown[r][c] or seen[r][c]:
                continue
            stack, cells = [(r, c)], []
            seen[r][c] = True
            while stack:
                y, x = stack.pop()
                cells.append((y, x))
                for ny, nx in ((y + 1, x), (y - 1, x), (y, x + 1), (y, x - 1)):
                    if 0 <= ny < rows and 0 <= nx < cols and grown[ny][nx] and not seen[ny][nx]:
                        seen[ny][nx] = True
                        stack.append((ny, nx))
            inked = [(y, x) for y, x in cells if ink[y][x]]  # its size is its ink's, not the grown cells'
            top, bottom = min(y for y, _ in inked), max(y for y, _ in inked) + 1
            left, right = min(x for _, x in inked), max(x for _, x in inked) + 1
            share = len(inked) / float((bottom - top) * (right - left))
            if (right - left) * cell_points >= min_inches[0] * 72 and (bottom - top) * cell_points >= min_inches[1] * 72 \
                    and share >= min_ink:
                regions.append((left * cell_points, top * cell_points, right * cell_points, bottom * cell_points))
    return sorted(regions, key=lambda box: (box[1], box[0]))


def cut_out(image, region, boxes, scale):
    """The part ``region`` (points) of the page's ``image`` (``scale`` pixels a point), the text layer's
    words ``boxes`` painted white: what is left is the picture's own ink."""
    x0, y0, x1, y1 = [int(round(v * scale)) for v in region]
    crop = image.crop((max(0, x0), max(0, y0), min(image.size[0], x1), min(image.size[1], y1))).copy()
    gray = ImageOps.grayscale(crop) if crop.mode != 'L' else crop
    draw = ImageDraw.Draw(gray)
    fill = 0 if dark(gray) else 255
    for bx0, by0, bx1, by1 in boxes:
        draw.rectangle([bx0 * scale - x0 - 1, by0 * scale - y0 - 1, bx1 * scale - x0 + 1, by1 * scale - y0 + 1], fill=fill)
    return gray
