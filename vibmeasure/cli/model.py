"""The ``model`` command: what a TOML model predicts."""

from __future__ import annotations

import argparse

from ._common import emit_json


def register(sub) -> None:
    """Add the command's parser to the subparsers ``sub``."""
    from ..core.model_format import TOML_FORMAT
    md = sub.add_parser("model", help="predictions of a model described in a TOML file",
                        description="Natural frequencies and damping a model predicts (vm.models.load).",
                        epilog=TOML_FORMAT, formatter_class=argparse.RawDescriptionHelpFormatter)
    md.add_argument("file", help="model.toml")
    md.add_argument("--modes", type=int, default=3, help="modes of a continuum (default 3)")
    md.add_argument("--json", action="store_true", help="print one JSON document")


def run(args, out, err) -> int:
    """The model's natural frequencies and damping, printed (or one JSON document)."""
    from ..models import load
    model = load(args.file)
    est = predict(model, args.modes)
    if args.json:
        emit_json({"command": "model", "file": str(args.file), "model": repr(model),
                   "modes": est.to_dict()["modes"]}, out)
    else:
        print(f"{args.file}: {model!r}", file=out)
        for i in range(est.n_modes):
            print(f"  mode {i + 1}: fn {est.fn[i]:.6g} Hz  zeta {est.zeta[i]:.5g}", file=out)
    return 0

def predict(model, n):
    """The modes a model predicts: n modes of a continuum, every mode of a discrete model."""
    from ..models import Beam, RayleighBeam, Rod, String, TimoshenkoBeam
    continua = (Beam, RayleighBeam, TimoshenkoBeam, Rod, String)
    return model.modes(n) if isinstance(model, continua) else model.modes()
