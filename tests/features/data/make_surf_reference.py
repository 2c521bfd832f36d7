"""Generate SURF reference values from the current main code (before the speed changes)."""
import subprocess, numpy as np, cv2
from scipy import ndimage
import slamlab.features as F
from slamlab.features import surf_detect

def synthetic(seed=7, shape=(288, 384)):
    rng = np.random.default_rng(seed)
    img = ndimage.gaussian_filter(rng.random(shape), 3.0)
    img = (img - img.min()) / (img.max() - img.min())
    yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
    for _ in range(15):
        cy, cx, s = rng.uniform(0, shape[0]), rng.uniform(0, shape[1]), rng.uniform(2, 25)
        img += rng.choice([-0.5, 0.5]) * np.exp(-((xx - cx) ** 2 + (yy - cy) ** 2) / (2 * s * s))
    return np.clip(img, 0, 1)

out = {}
commit = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True, check=False).stdout.strip()
img = synthetic()
for name, kw in (("syn", {}), ("syn_ext", {"extended": True}), ("syn_up", {"upright": True})):
    f = surf_detect(img, 1e-3, **kw)
    out.update({f"{name}_uv": f.uv, f"{name}_scale": f.scale_px, f"{name}_ori": f.orientation_rad,
                f"{name}_resp": f.response, f"{name}_octave": f.octave, f"{name}_desc": f.descriptors})
    print(name, f.uv.shape)
g = cv2.resize(F.load_oxford_image("graf", 1), (768, 576), interpolation=cv2.INTER_AREA)
f = surf_detect(g, 4e-4)
out.update({"graf_uv": f.uv, "graf_scale": f.scale_px, "graf_ori": f.orientation_rad, "graf_resp": f.response,
            "graf_octave": f.octave, "graf_desc": f.descriptors})
print("graf", f.uv.shape)
np.savez_compressed("tests/features/data/surf_reference.npz", commit=np.array(commit), **out)
