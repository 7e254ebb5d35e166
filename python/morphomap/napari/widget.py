"""The plugin's widget: a labels movie in the viewer mapped by :func:`morphomap.map_series` in a
thread worker, its results added as layers and its quality shown in a table.

Every failure (no labels layer, an empty object, a pair that cannot be mapped, a folder that
cannot be written) is shown as a napari error notification; nothing raises out of the viewer.
"""

from __future__ import annotations

import warnings

import numpy as np
from napari.layers import Labels
from napari.qt.threading import create_worker
from napari.utils.notifications import show_error, show_info, show_warning
from qtpy.QtWidgets import (QComboBox, QDoubleSpinBox, QFileDialog, QFormLayout, QLabel, QPushButton, QSpinBox,
                            QTableWidget, QTableWidgetItem, QVBoxLayout, QWidget)

from .compute import CHOICES, DRIFT, Options, check_labels, map_labels, methods
from .layers import series_layers

#: The quality table's columns: a title and how to read it off a row of ``series.quality``.
COLUMNS = (("step", lambda q: str(q.step)), ("QM1", lambda q: f"{q.qm1:.3f}"), ("QM2", lambda q: f"{q.qm2:.3f}"),
           ("QM", lambda q: f"{q.qm:.3f}"), ("crossings", lambda q: str(q.defects)),
           ("misses", lambda q: str(q.misses)))
#: The smoothing box's lowest value stands for None (the mask readers' own default width).
AUTO_SMOOTH = -0.1


def _map_in_steps(data, spacing, options, dt, unit, scale, translate):
    """The worker: map, then make the layers' data; yields once per stage for the progress bar.
    Warnings (an object touching the border, one in several parts) are returned to be shown."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        series = map_labels(data, spacing, options, dt=dt, unit=unit)
        yield "mapped"
        layers = series_layers(series, spacing, scale, translate)
        yield "layers"
    return series, layers, [str(w.message) for w in caught]


class SeriesWidget(QWidget):
    """Map a Labels movie (2D + t or 3D + t) through time and show the result.

    Parameters
    ----------
    napari_viewer : napari.viewer.Viewer
        The viewer whose Labels layers are offered and which receives the results.

    Attributes
    ----------
    series : morphomap.series.Series or None
        The last result.
    busy : bool
        Whether a worker (mapping or writing) is running; tests wait on it.
    """

    def __init__(self, napari_viewer):
        super().__init__()
        self.viewer = napari_viewer
        self.series, self.busy, self._source = None, False, None
        self.labels = QComboBox()
        self.objects = QComboBox()
        self.objects.addItems(CHOICES)
        self.label = QSpinBox()
        self.label.setRange(0, 2**31 - 1)
        self.label.setSpecialValueText("none")
        self.smooth = QDoubleSpinBox()
        self.smooth.setRange(AUTO_SMOOTH, 1e4)
        self.smooth.setSingleStep(0.1)
        self.smooth.setDecimals(2)
        self.smooth.setSpecialValueText("auto")
        self.smooth.setValue(AUTO_SMOOTH)
        self.method = QComboBox()
        self.drift = QComboBox()
        self.drift.addItems(DRIFT)
        self.run_button = QPushButton("Map series")
        self.write_button = QPushButton("Write series folder…")
        self.write_button.setEnabled(False)
        self.status = QLabel("")
        self.status.setWordWrap(True)
        self.table = QTableWidget(0, len(COLUMNS))
        self.table.setHorizontalHeaderLabels([title for title, _ in COLUMNS])
        form = QFormLayout()
        for title, box in (("labels", self.labels), ("object", self.objects), ("label", self.label),
                           ("smoothing", self.smooth), ("method", self.method), ("drift", self.drift)):
            form.addRow(title, box)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        for item in (self.run_button, self.status, self.table, self.write_button):
            layout.addWidget(item)
        self.run_button.clicked.connect(self.run)
        self.write_button.clicked.connect(lambda: self.write())
        self.labels.currentIndexChanged.connect(self._offer_methods)
        for event in (napari_viewer.layers.events.inserted, napari_viewer.layers.events.removed,
                      napari_viewer.layers.events.moved):
            event.connect(self._offer_layers)
        self._offer_layers()

    # -- what the widget offers --------------------------------------------------------------
    def _labels_layers(self) -> list:
        return [layer for layer in self.viewer.layers if isinstance(layer, Labels)]

    def _offer_layers(self, *_):
        current = self.labels.currentText()
        names = [layer.name for layer in self._labels_layers()]
        self.labels.blockSignals(True)
        self.labels.clear()
        self.labels.addItems(names)
        if current in names:
            self.labels.setCurrentText(current)
        self.labels.blockSignals(False)
        self._offer_methods()

    def _offer_methods(self, *_):
        layer = self.layer()
        dim = 3 if layer is not None and layer.data.ndim == 4 else 2
        current = self.method.currentText() or "auto"
        self.method.clear()
        self.method.addItems(methods(dim))
        self.method.setCurrentText(current if current in methods(dim) else "auto")
        self.table.setHorizontalHeaderItem(4, QTableWidgetItem("crossings" if dim == 2 else "folds"))

    def layer(self):
        """The chosen Labels layer, or None."""
        name = self.labels.currentText()
        return next((layer for layer in self._labels_layers() if layer.name == name), None)

    def options(self) -> Options:
        """The settings as :func:`morphomap.napari.compute.map_labels` takes them."""
        smooth = self.smooth.value()
        return Options(objects=self.objects.currentText(), label=self.label.value() or None,
                       smooth=None if smooth <= AUTO_SMOOTH / 2 else float(smooth),
                       method=self.method.currentText(), drift=self.drift.currentText())

    # -- mapping -------------------------------------------------------------------------------
    def run(self):
        """Map the chosen layer in a thread worker (napari's progress bar counts its stages) and
        add the results as layers. Returns the worker, or None where the input is refused (with
        an error notification)."""
        if self.busy:
            show_info("morphomap: a series is already being mapped")
            return None
        try:
            layer = self.layer()
            if layer is None:
                raise ValueError("labels: no Labels layer to map; open or add a labels movie (time first)")
            spacing = tuple(float(v) for v in layer.scale[1:])
            data, spacing = check_labels(layer.data, spacing)
            metadata = layer.metadata or {}
            dt, unit = metadata.get("frame_interval"), metadata.get("unit")
            scale, translate = tuple(layer.scale), tuple(layer.translate)
            options = self.options()
        except (ValueError, TypeError) as error:
            show_error(f"morphomap: {error}")
            return None
        self.busy, self._source = True, layer.name
        self.status.setText(f"mapping {layer.name}…")
        return create_worker(_map_in_steps, np.asarray(data), spacing, options, dt, unit, scale, translate,
                             _progress={"total": 2, "desc": "morphomap: mapping"},
                             _connect={"returned": self._show, "errored": self._failed, "finished": self._idle})

    def _show(self, result):
        series, layers, said = result
        try:
            for message in dict.fromkeys(said):
                show_warning(f"morphomap: {message}")
            for data, options, kind in layers:
                name = f"{self._source} {options['name']}"
                if name in self.viewer.layers:
                    self.viewer.layers.remove(name)
                getattr(self.viewer, f"add_{kind}")(data, **dict(options, name=name))
        except Exception as error:  # a layer napari refuses must not take the viewer down
            show_error(f"morphomap: the results could not be shown: {error}")
            return
        self.series = series
        self._fill_table(series)
        self.write_button.setEnabled(True)
        lost = int(np.isnan(series.trajectories[-1]).any(axis=1).sum())
        self.status.setText(f"{len(series.frames)} frames, {series.trajectories.shape[1]} points followed, "
                            f"{lost} lost")

    def _fill_table(self, series):
        self.table.setRowCount(len(series.quality))
        for row, q in enumerate(series.quality):
            for column, (_, read) in enumerate(COLUMNS):
                self.table.setItem(row, column, QTableWidgetItem(read(q)))
        self.table.resizeColumnsToContents()

    def _failed(self, error):
        self.status.setText("failed")
        show_error(f"morphomap: {error}")

    def _idle(self, *_):
        self.busy = False

    # -- writing -------------------------------------------------------------------------------
    def write(self, folder=None):
        """Write the last series into ``folder`` (:meth:`morphomap.series.Series.write`; asked for
        with a dialog when None) in a thread worker. Returns the worker, or None."""
        if self.series is None:
            show_error("morphomap: nothing to write yet; map a series first")
            return None
        if folder is None:
            folder = QFileDialog.getExistingDirectory(self, "Write the series into")
            if not folder:
                return None
        self.busy = True
        self.status.setText(f"writing {folder}…")
        return create_worker(self.series.write, folder, _progress={"total": 0, "desc": "morphomap: writing"},
                             _connect={"returned": lambda paths: self._written(folder, paths),
                                       "errored": self._failed, "finished": self._idle})

    def _written(self, folder, paths):
        self.status.setText(f"wrote {len(paths)} files into {folder}")
        show_info(f"morphomap: wrote {len(paths)} files into {folder}")
