"""cellsph.neighbors / count_neighbors / NeighborSearch against SciPy's cKDTree (an independent search)."""
import threading

import numpy as np
import pytest
from scipy.spatial import cKDTree

import cellsph


def rows_of(offsets, indices):
    return [list(indices[offsets[i] : offsets[i + 1]]) for i in range(len(offsets) - 1)]


def reference_rows(points, r):
    """cKDTree.query_ball_point without the point itself, sorted. r: scalar or per-point array."""
    tree = cKDTree(points.astype(np.float64))
    lists = tree.query_ball_point(points.astype(np.float64), r, return_sorted=True)
    return [[j for j in row if j != i] for i, row in enumerate(lists)]


def random_set(n, dim, dtype, seed):
    return np.random.default_rng(seed).random((n, dim)).astype(dtype)


def lattice(dim, side, spacing=0.25, dtype=np.float64):
    """A side^dim lattice of spacing 0.25: every coordinate, difference and square is exact in float32."""
    axes = [np.arange(side) * spacing] * dim
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, dim).astype(dtype)


def gap_radius(points, target):
    """A radius near `target` that no pair distance comes close to (the middle of the widest gap between
    the sorted pair distances within 5% of it), so float32 rounding cannot put a pair on the other side
    in one search and not in the other. Returns (radius, margin relative to the radius)."""
    p = points.astype(np.float64)
    pairs = cKDTree(p).query_pairs(target * 1.05, output_type="ndarray")
    d = np.sort(np.linalg.norm(p[pairs[:, 0]] - p[pairs[:, 1]], axis=1))
    d = d[d >= target * 0.95]
    k = int(np.argmax(np.diff(d)))
    r = 0.5 * (d[k] + d[k + 1])
    return r, 0.5 * (d[k + 1] - d[k]) / r


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_random_set_equals_ckdtree(dim, dtype):
    points = random_set(3000, dim, dtype, seed=dim)
    r, margin = gap_radius(points, 0.05 if dim == 2 else 0.1)
    assert margin > 1e-6  # far beyond float32 rounding of a distance (~1e-7 relative)
    offsets, indices = cellsph.neighbors(points, radius=r)
    assert offsets.dtype == np.int64 and indices.dtype == np.uint32
    assert offsets.shape == (len(points) + 1,) and offsets[-1] == len(indices)
    ref = reference_rows(points, r)
    assert sum(map(len, ref)) > 10 * len(points)  # a real test: many neighbours per point
    assert rows_of(offsets, indices) == ref
    # query_pairs: the unordered pairs are the upper triangle of our (symmetric) lists.
    pairs = cKDTree(points.astype(np.float64)).query_pairs(r, output_type="ndarray")
    rows = np.repeat(np.arange(len(points)), np.diff(offsets))
    upper = np.stack([rows, indices.astype(np.int64)], axis=1)
    upper = upper[upper[:, 0] < upper[:, 1]]
    assert np.array_equal(upper, pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))])


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_lattice_with_pairs_exactly_at_the_radius(dim, dtype):
    points = lattice(dim, 24 if dim == 2 else 10, dtype=dtype)
    offsets, indices = cellsph.neighbors(points, radius=0.5)  # 2 spacings: neighbours exactly at r count
    ref = reference_rows(points, 0.5)
    assert rows_of(offsets, indices) == ref
    interior = np.all((points >= 0.5) & (points <= points.max() - 0.5), axis=1)
    expected = {2: 12, 3: 32}[dim]  # lattice points within 2 spacings, the point itself excluded
    assert np.all(np.diff(offsets)[interior] == expected)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_per_point_support_on_a_lattice(dim, dtype):
    points = lattice(dim, 20 if dim == 2 else 9, dtype=dtype)
    h = np.random.default_rng(5).integers(0, 4, len(points)) * 0.25  # 0, 0.25, 0.5, 0.75: exact ties
    offsets, indices = cellsph.neighbors(points, h=h)
    assert rows_of(offsets, indices) == reference_rows(points, h)
    assert np.all(np.diff(offsets)[h == 0] == 0)


def test_per_point_support_random_float64():
    points = random_set(2000, 3, np.float64, seed=11)
    h = np.random.default_rng(12).uniform(0.02, 0.15, len(points))
    offsets, indices = cellsph.neighbors(points, h=h)
    assert rows_of(offsets, indices) == reference_rows(points, h)


@pytest.mark.parametrize("method", ["all-pairs", "spatial-hash", "cell-index", "sorted-grid", "kd-tree"])
def test_every_method_gives_the_reference(method):
    points = random_set(1500, 3, np.float64, seed=3)
    offsets, indices = cellsph.neighbors(points, radius=0.09, method=method, subdivision=2)
    assert rows_of(offsets, indices) == reference_rows(points, 0.09)
    assert cellsph.methods() == ["all-pairs", "spatial-hash", "cell-index", "sorted-grid", "kd-tree"]


def test_thread_counts_give_the_same_arrays():
    points = random_set(20000, 3, np.float32, seed=4)
    a = cellsph.neighbors(points, radius=0.04, threads=1)
    b = cellsph.neighbors(points, radius=0.04, threads=2)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_unsorted_rows_hold_the_reference_sets_in_the_searchs_order():
    points = random_set(20000, 3, np.float64, seed=12)
    ref = reference_rows(points, 0.04)
    a = cellsph.neighbors(points, radius=0.04, sort_rows=False, threads=1)
    b = cellsph.neighbors(points, radius=0.04, sort_rows=False, threads=2, return_distances=True)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])  # the order is the search's, not the threads'
    rows = rows_of(a[0], a[1])
    assert any(row != sorted(row) for row in rows)  # the option reached the search
    assert [sorted(row) for row in rows] == ref
    r = np.repeat(np.arange(len(points)), np.diff(b[0]))
    np.testing.assert_allclose(b[2], np.linalg.norm(points[r] - points[b[1]], axis=1), rtol=1e-14)
    # The reusable object keeps the option; another method's rows stay ascending.
    ns = cellsph.NeighborSearch(sort_rows=False)
    assert ns.sort_rows is False and cellsph.NeighborSearch().sort_rows is True
    ns.build(points, radius=0.04)
    offsets, indices = ns.find_all()
    assert np.array_equal(offsets, a[0]) and np.array_equal(indices, a[1])
    kd = cellsph.neighbors(points, radius=0.04, method="kd-tree", sort_rows=False)
    assert rows_of(*kd) == ref


def test_count_neighbors_and_distances():
    points = random_set(2000, 2, np.float64, seed=6)
    offsets, indices, dist = cellsph.neighbors(points, radius=0.05, return_distances=True)
    counts = cellsph.count_neighbors(points, radius=0.05)
    assert counts.dtype == np.int64
    assert np.array_equal(counts, [len(r) for r in reference_rows(points, 0.05)])
    assert np.array_equal(counts, np.diff(offsets))
    rows = np.repeat(np.arange(len(points)), counts)
    np.testing.assert_allclose(dist, np.linalg.norm(points[rows] - points[indices], axis=1), rtol=1e-14)
    assert np.all(dist <= 0.05)


def test_neighbor_matrix_equals_sparse_distance_matrix():
    points = random_set(1500, 3, np.float64, seed=8)
    ours = cellsph.neighbor_matrix(points, radius=0.1)
    tree = cKDTree(points)
    theirs = tree.sparse_distance_matrix(tree, 0.1).tocsr()
    theirs.setdiag(0)
    theirs.eliminate_zeros()  # SciPy lists each point as its own neighbour at distance 0
    assert ours.shape == theirs.shape and ours.nnz == theirs.nnz
    assert abs(ours - theirs).max() < 1e-15
    adjacency = cellsph.to_csr(*cellsph.neighbors(points, radius=0.1))
    assert np.array_equal(adjacency.indices, ours.indices) and np.all(adjacency.data == 1)


def test_empty_and_single_point_sets():
    offsets, indices = cellsph.neighbors(np.zeros((0, 3)), radius=1.0)
    assert list(offsets) == [0] and len(indices) == 0
    offsets, indices = cellsph.neighbors(np.zeros((1, 2), np.float32), radius=1.0)
    assert list(offsets) == [0, 0] and len(indices) == 0


def test_strided_and_list_inputs():
    points = random_set(3000, 3, np.float64, seed=9)
    strided = points[::2]
    assert not strided.flags.c_contiguous
    a = cellsph.neighbors(strided, radius=0.1)
    b = cellsph.neighbors(np.ascontiguousarray(strided), radius=0.1)
    assert np.array_equal(a[1], b[1])
    c = cellsph.neighbors(strided.tolist(), radius=0.1)  # float64 array-like
    assert np.array_equal(a[1], c[1])


def test_arrays_outlive_the_search():
    offsets, indices = cellsph.neighbors(lattice(2, 10), radius=0.3)
    del offsets
    assert indices.base is not None  # owned by the search's output, not copied
    assert int(indices.sum()) > 0


def test_neighbor_search_object_on_moving_points():
    rng = np.random.default_rng(10)
    points = rng.random((5000, 3))
    ns = cellsph.NeighborSearch(method="cell-index", threads=2)
    with pytest.raises(ValueError, match="call build"):
        ns.find_all()
    for _ in range(4):
        points += rng.normal(scale=0.01, size=points.shape)
        ns.build(points, radius=0.06)
        offsets, indices = ns.find_all()
        assert rows_of(offsets, indices) == reference_rows(points, 0.06)
        assert np.array_equal(ns.count(), np.diff(offsets))
    assert ns.size == 5000 and ns.dim == 3 and ns.dtype == np.float64 and ns.method == "cell-index"
    assert set(ns.stats) == {"build_ms", "query_ms", "pairs", "candidates", "memory_bytes"}
    assert ns.stats["pairs"] == len(indices)
    ns.build(points[:, :2].astype(np.float32), radius=0.05)  # another dimension and dtype: same object
    assert ns.dim == 2 and ns.dtype == np.float32
    o2, i2, d2 = ns.find_all(return_distances=True)
    assert d2.dtype == np.float32 and len(d2) == len(i2)


def test_concurrent_searches_from_python_threads():
    points = random_set(20000, 3, np.float64, seed=13)
    expected = cellsph.neighbors(points, radius=0.04)
    results = [None] * 4

    def work(k):
        results[k] = cellsph.neighbors(points, radius=0.04, threads=1)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert np.array_equal(r[0], expected[0]) and np.array_equal(r[1], expected[1])


GOOD = np.zeros((4, 3))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(points=np.zeros((4,))), r"points: shape \(4,\), expected \(n, 2\) or \(n, 3\)"),
        (dict(points=np.zeros((4, 4))), r"points: shape \(4, 4\)"),
        (dict(points=np.zeros((4, 3), np.int64)), "points: dtype int64, expected float32 or float64"),
        (dict(points=np.zeros((4, 3), np.float16)), "points: dtype float16"),
        (dict(points="abc"), "points: dtype <U3"),
        (dict(points=np.array([[0, 0, 0], [1, np.nan, 0]], float)), "points: row 1, column 1 is nan"),
        (dict(points=np.array([[0, 0], [1, np.inf]], np.float32)), "points: row 1, column 1 is inf"),
        (dict(radius=-1.0), "radius: must be a finite number > 0, got -1"),
        (dict(radius=0.0), "radius: must be a finite number > 0, got 0"),
        (dict(radius=float("nan")), "radius: must be a finite number > 0, got nan"),
        (dict(radius=None), "radius: required"),
        (dict(radius=1.0, h=np.ones(4)), "radius and h: give one, not both"),
        (dict(radius=None, h=np.ones(3)), r"h: shape \(3,\), expected \(4,\)"),
        (dict(radius=None, h=np.array([1, 1, -0.5, 1])), r"h\[2\] = -0.5: support lengths must be finite and >= 0"),
        (dict(radius=None, h=np.array([1, np.nan, 1, 1])), r"h\[1\] = nan"),
        (dict(radius=None, h=np.array(["a"] * 4)), "h: dtype <U1"),
        (dict(method="octree"), "method: unknown method 'octree'"),
        (dict(threads=-2), "threads: must be >= 1, or 0 for all cores; got -2"),
        (dict(subdivision=0), "subdivision: must be an integer >= 1, got 0"),
    ],
)
@pytest.mark.parametrize("function", [cellsph.neighbors, cellsph.count_neighbors])
def test_bad_arguments_raise_value_error(function, kwargs, match):
    args = dict(points=GOOD, radius=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        function(**args)


def test_bad_arguments_of_the_search_object():
    with pytest.raises(ValueError, match="method: unknown method 'fast'"):
        cellsph.NeighborSearch(method="fast")
    ns = cellsph.NeighborSearch()
    with pytest.raises(ValueError, match="points: row 0, column 0 is nan"):
        ns.build(np.full((2, 2), np.nan), radius=1.0)
    with pytest.raises(ValueError, match="radius: must be a finite number > 0, got -3"):
        ns.build(GOOD, radius=-3.0)
    assert ns.size == 0  # nothing was built
    # Points far beyond what a key's cells span are searched exactly (the grid is cut at its last cell).
    ns.build(np.array([[0, 0, 0], [1e30, 0, 0], [1e30, 0, 1e-21]]), radius=1e-20)
    offsets, indices = ns.find_all()
    assert offsets.tolist() == [0, 0, 1, 2] and indices.tolist() == [2, 1]
    ns = cellsph.NeighborSearch()
    with pytest.raises(ValueError, match="call build"):
        ns.find_all()
