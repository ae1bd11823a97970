"""Bad-input specs of the JSON and optional-engine helpers of robomech.verify."""

import numpy as np
from contract_spec import BAD_STR, Exempt, Spec

P = "robomech.verify."

SPECS = {
    P + "EngineUnavailable": Exempt(
        "exception type (an ImportError): raised by the library, takes a message"
    ),
    P + "to_jsonable": Spec(args={"obj": {"a": np.array([1.0, 2.0])}}, options={"obj": (1j, object(), {1j})}),
    P + "dumps_json": Spec(
        args={"obj": {"a": np.float64(1.0)}, "indent": 2},
        options={"obj": (1j, object()), "indent": (-1, "2", 1.5, True)},
    ),
    P + "optional_module": Spec(args={"name": "json"}, options={"name": (*BAD_STR, "", "a b", "1x")}),
}
